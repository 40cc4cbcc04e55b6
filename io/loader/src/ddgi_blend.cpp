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

float DdgiVolume::blend_weight(const Vec3& p) const {
  float w = 1.f;
  for (int a = 0; a < 3; ++a) {
    float g = 0.f, last = 0.f;
    if (!grid_coordinate(desc_, p, a, g, last)) continue;
    if (!std::isfinite(g)) return 0.f;
    // Cells from the region's nearer face along this axis, minus half: 0.5 + distance inside the
    // probe box in spacings. The fade is one spacing wide, centred on the outermost probe layer.
    const float to_face = last - g;
    const float inside = 0.5f + (to_face < g ? to_face : g);
    w *= inside < 0.f ? 0.f : (inside > 1.f ? 1.f : inside);
  }
  return w;
}

bool DdgiVolume::region_contains(const Vec3& p) const {
  for (int a = 0; a < 3; ++a) {
    float g = 0.f, last = 0.f;
    if (!grid_coordinate(desc_, p, a, g, last)) continue;
    if (!(g >= -0.5f && g <= last + 0.5f)) return false;  // NaN: outside
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
    const float cells = g < -0.5f ? -0.5f - g : (g > last + 0.5f ? g - (last + 0.5f) : 0.f);
    const float metres = cells * desc_.spacing[a];
    sum += metres * metres;
  }
  return std::sqrt(sum);
}

float DdgiVolume::finest_spacing() const {
  float s = std::numeric_limits<float>::infinity();
  for (int a = 0; a < 3; ++a)
    if (desc_.counts[a] > 1 && desc_.spacing[a] > 0.f) s = std::min(s, desc_.spacing[a]);
  return s;
}

void BakeFile::order_ddgi_volumes() {
  ddgi_order_.resize(volumes_.size());
  std::iota(ddgi_order_.begin(), ddgi_order_.end(), 0u);
  std::stable_sort(ddgi_order_.begin(), ddgi_order_.end(), [this](uint32_t a, uint32_t b) {
    return volumes_[a].finest_spacing() < volumes_[b].finest_spacing();
  });
}

bool BakeFile::sample_ddgi(const Vec3& p, const Vec3& n, Rgb& out, const SampleOptions& options) const {
  out = {0.f, 0.f, 0.f};
  Rgb sum{0.f, 0.f, 0.f}, lone{0.f, 0.f, 0.f};
  float taken = 0.f;
  int contributors = 0;
  const DdgiVolume* first_inside = nullptr;
  for (uint32_t i : ddgi_order_) {
    const DdgiVolume& v = volumes_[i];
    if (!v.region_contains(p)) continue;
    if (!first_inside) first_inside = &v;
    const float w = v.blend_weight(p);
    if (!(w > 0.f)) continue;
    Rgb e;
    if (!v.try_sample_irradiance(p, n, e, options)) continue;  // no usable probe here: the others answer
    // A volume of weight 1 takes all that is left, exactly (no rounding of taken + (1 - taken)).
    const float c = w >= 1.f ? 1.f - taken : w * (1.f - taken);
    for (int k = 0; k < 3; ++k) sum[size_t(k)] += c * e[size_t(k)];
    taken = w >= 1.f ? 1.f : taken + c;
    lone = e;
    ++contributors;
    if (taken >= 1.f) break;
  }
  if (!first_inside) {
    const DdgiVolume* nearest = nullptr;
    float best = std::numeric_limits<float>::infinity();
    for (uint32_t i : ddgi_order_) {
      const float d = volumes_[i].region_distance(p);
      if (!nearest || d < best) nearest = &volumes_[i], best = d;
    }
    if (nearest) out = nearest->sample_irradiance(p, n, options);
    return false;
  }
  if (contributors == 0) {
    out = first_inside->sample_irradiance(p, n, options);
  } else if (contributors == 1) {
    out = lone;  // w x E / w would round: a lone volume answers with its own bits
  } else {
    for (int k = 0; k < 3; ++k) out[size_t(k)] = taken < 1.f ? sum[size_t(k)] / taken : sum[size_t(k)];
  }
  return true;
}

}  // namespace gibake::loader
