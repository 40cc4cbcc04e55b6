// Several DDGI volumes in one file, blended the way RTXGI blends its volumes (docs/FORMAT.md
// "Several volumes"): finest first, each taking its blend weight of what the finer ones left.
// gibake/ddgi_sample.glsl's gibake_ddgi_blended_irradiance does the same operations in this order.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "gibake/loader.hpp"

namespace gibake::loader {
namespace {

// The probe-grid coordinate of p along axis a, or false on an axis of one probe (unbounded).
bool grid_coordinate(const gibake_ddgi_volume& d, const Vec3& p, int a, float& g, float& last) {
  if (d.counts[a] <= 1 || !(d.spacing[a] > 0.f)) return false;
  g = (p[size_t(a)] - d.grid_min[a]) / d.spacing[a];
  last = float(d.counts[a] - 1);
  return true;
}

}  // namespace

// The smallest spacing of an axis with more than one probe; infinity with none.
static float volume_finest_spacing(const gibake_ddgi_volume& d) {
  float s = std::numeric_limits<float>::infinity();
  for (int a = 0; a < 3; ++a)
    if (d.counts[a] > 1 && d.spacing[a] > 0.f) s = std::min(s, d.spacing[a]);
  return s;
}

std::vector<uint32_t> ddgi_priority_order(const std::vector<gibake_ddgi_volume>& volumes) {
  std::vector<uint32_t> order(volumes.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return volume_finest_spacing(volumes[a]) < volume_finest_spacing(volumes[b]);
  });
  return order;
}

float DdgiVolume::blend_weight(const Vec3& p) const {
  float w = 1.f;
  for (int a = 0; a < 3; ++a) {
    float g = 0.f, last = 0.f;
    if (!grid_coordinate(desc_, p, a, g, last)) continue;
    if (!std::isfinite(g)) return 0.f;
    // m: spacings inside the probe box (negative outside). 1 down to m = -1/2 (the volume's cells),
    // then linearly to 0 at m = -1 (one spacing beyond the outermost probe layer).
    const float to_face = last - g;
    const float m = to_face < g ? to_face : g;
    const float t = 2.f * (1.f + m);
    w *= t < 0.f ? 0.f : (t > 1.f ? 1.f : t);
  }
  return w;
}

bool DdgiVolume::region_contains(const Vec3& p) const {
  for (int a = 0; a < 3; ++a) {
    float g = 0.f, last = 0.f;
    if (!grid_coordinate(desc_, p, a, g, last)) continue;
    if (!(g >= -1.f && g <= last + 1.f)) return false;  // NaN: outside
  }
  return true;
}

float DdgiVolume::region_distance(const Vec3& p) const {
  // Float operations in the GLSL include's order (gibake_ddgi_region_distance).
  float sum = 0.f;
  for (int a = 0; a < 3; ++a) {
    float g = 0.f, last = 0.f;
    if (!grid_coordinate(desc_, p, a, g, last)) continue;
    if (!std::isfinite(g)) return std::numeric_limits<float>::infinity();
    const float cells = g < -1.f ? -1.f - g : (g > last + 1.f ? g - (last + 1.f) : 0.f);
    const float metres = cells * desc_.spacing[a];
    sum += metres * metres;
  }
  return std::sqrt(sum);
}

float DdgiVolume::finest_spacing() const { return volume_finest_spacing(desc_); }

void BakeFile::order_ddgi_volumes() {
  std::vector<gibake_ddgi_volume> descs;
  for (const DdgiVolume& v : volumes_) descs.push_back(v.desc());
  ddgi_order_ = ddgi_priority_order(descs);
}

namespace {

// The blend over the volumes `next` hands out (priority order); false when none of their regions
// holds p (out untouched then). `shares` (optional) receives the volumes the answer came from.
template <class Next>
bool blend(const std::vector<DdgiVolume>& volumes, Next&& next, const Vec3& p, const Vec3& n, Rgb& out,
           const SampleOptions& options, std::vector<VolumeShare>* shares = nullptr) {
  Rgb sum{0.f, 0.f, 0.f}, lone{0.f, 0.f, 0.f}, unseen_answer{0.f, 0.f, 0.f};
  float taken = 0.f;
  int contributors = 0;
  const DdgiVolume* first_inside = nullptr;
  const DdgiVolume* unseen = nullptr;  // the first volume with an answer that no probe of its sees
  for (uint32_t i = 0; next(i);) {
    const DdgiVolume& v = volumes[i];
    if (!v.region_contains(p)) continue;
    if (!first_inside) first_inside = &v;
    const float region = v.blend_weight(p);
    if (!(region > 0.f)) continue;
    Rgb e;
    float sight = 0.f;
    if (!v.try_sample_irradiance(p, n, e, sight, options)) continue;  // no usable probe here: the others answer
    // A volume whose probes barely see p answers with the floor's weights: trust it that much less.
    const float w = sight >= GIBAKE_DDGI_FULL_SIGHT ? region : region * (sight / GIBAKE_DDGI_FULL_SIGHT);
    if (!(w > 0.f)) {
      if (!unseen) unseen = &v, unseen_answer = e;
      continue;
    }
    // A volume of weight 1 takes all that is left, exactly (no rounding of taken + (1 - taken)).
    const float c = w >= 1.f ? 1.f - taken : w * (1.f - taken);
    for (int k = 0; k < 3; ++k) sum[size_t(k)] += c * e[size_t(k)];
    if (shares) shares->push_back({i, c});
    taken = w >= 1.f ? 1.f : taken + c;
    lone = e;
    ++contributors;
    if (taken >= 1.f) break;
  }
  if (!first_inside) return false;
  const DdgiVolume* alone = unseen ? unseen : first_inside;  // answers when no volume contributes
  if (shares && contributors == 0) shares->push_back({uint32_t(alone - volumes.data()), 1.f});
  if (shares && contributors == 1) shares->back().share = 1.f;
  if (shares && contributors > 1 && taken < 1.f)
    for (VolumeShare& v : *shares) v.share /= taken;
  if (contributors == 0) {
    out = unseen ? unseen_answer : first_inside->sample_irradiance(p, n, options);
  } else if (contributors == 1) {
    out = lone;  // w x E / w would round: a lone volume answers with its own bits
  } else {
    for (int k = 0; k < 3; ++k) out[size_t(k)] = taken < 1.f ? sum[size_t(k)] / taken : sum[size_t(k)];
  }
  return true;
}

// The volume whose region is nearest p (by region distance, then priority): null without volumes.
const DdgiVolume* nearest_volume(const std::vector<DdgiVolume>& volumes, const std::vector<uint32_t>& order,
                                 const Vec3& p) {
  const DdgiVolume* nearest = nullptr;
  float best = std::numeric_limits<float>::infinity();
  for (uint32_t i : order) {
    const float d = volumes[i].region_distance(p);
    if (!nearest || d < best) nearest = &volumes[i], best = d;
  }
  return nearest;
}

}  // namespace

bool BakeFile::sample_ddgi_unindexed(const Vec3& p, const Vec3& n, Rgb& out, const SampleOptions& options) const {
  out = {0.f, 0.f, 0.f};
  size_t k = 0;
  const auto next = [&](uint32_t& id) { return k < ddgi_order_.size() ? (id = ddgi_order_[k++], true) : false; };
  if (blend(volumes_, next, p, n, out, options)) return true;
  const DdgiVolume* nearest = nearest_volume(volumes_, ddgi_order_, p);
  if (nearest) out = nearest->sample_irradiance(p, n, options);
  return false;
}

// The cell's list holds every volume whose region can hold p, in priority order: the volumes left
// out are exactly ones the loop skips at its first test, so the answer is the loop's to the bit.
bool BakeFile::sample_ddgi(const Vec3& p, const Vec3& n, Rgb& out, const SampleOptions& options) const {
  uint32_t cell = 0;
  if (index_.present() && index_.cell_of(p, cell)) {
    const uint32_t size = index_.list_size(cell);
    uint32_t k = 0;
    const auto next = [&](uint32_t& id) { return k < size ? (id = index_.list_id(cell, k++), true) : false; };
    out = {0.f, 0.f, 0.f};
    if (size > 0 && blend(volumes_, next, p, n, out, options)) return true;
  }
  return sample_ddgi_unindexed(p, n, out, options);
}

std::vector<VolumeShare> BakeFile::ddgi_shares(const Vec3& p, const Vec3& n, const SampleOptions& options) const {
  std::vector<VolumeShare> shares;
  size_t k = 0;
  const auto next = [&](uint32_t& id) { return k < ddgi_order_.size() ? (id = ddgi_order_[k++], true) : false; };
  Rgb unused;
  if (blend(volumes_, next, p, n, unused, options, &shares)) return shares;
  shares.clear();
  const DdgiVolume* nearest = nearest_volume(volumes_, ddgi_order_, p);
  if (nearest) shares.push_back({uint32_t(nearest - volumes_.data()), 1.f});
  return shares;
}

}  // namespace gibake::loader
