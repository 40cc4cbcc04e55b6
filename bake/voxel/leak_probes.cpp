#include "bake/voxel/leak_probes.h"

#include <algorithm>
#include <cmath>

#include "kernels/vec.h"

namespace gibake {
namespace {

using kernels::float3;

struct CornerProbe {
  int32_t index = 0;
  float3 position{};
};

// The (up to 8) probes of the cell around `x`, clamped to the grid.
std::vector<CornerProbe> cell_corners(const DdgiResult& r, const std::array<float, 3>& x) {
  const DdgiVolumeDesc& d = r.desc;
  int32_t lo[3];
  int32_t n[3];
  for (int a = 0; a < 3; ++a) {
    n[a] = d.counts[a] > 1 ? 2 : 1;
    const float g = d.spacing[a] > 0.f ? (x[size_t(a)] - d.grid_min[size_t(a)]) / d.spacing[a] : 0.f;
    lo[a] = std::clamp(int32_t(std::floor(g)), 0, std::max(0, d.counts[a] - 2));
  }
  std::vector<CornerProbe> out;
  for (int32_t k = 0; k < n[2]; ++k)
    for (int32_t j = 0; j < n[1]; ++j)
      for (int32_t i = 0; i < n[0]; ++i) {
        const int32_t c[3] = {lo[0] + i, lo[1] + j, lo[2] + k};
        CornerProbe p;
        p.index = c[0] + d.counts[0] * (c[1] + d.counts[1] * c[2]);
        const float* off = &r.offsets[size_t(p.index) * 3];
        p.position = {d.grid_min[0] + d.spacing[0] * float(c[0]) + off[0],
                      d.grid_min[1] + d.spacing[1] * float(c[1]) + off[1],
                      d.grid_min[2] + d.spacing[2] * float(c[2]) + off[2]};
        out.push_back(p);
      }
  return out;
}

float dc_luminance(const DdgiResult& r, int32_t probe) {
  const float* c = &r.sh[size_t(probe) * size_t(r.desc.sh_coefficients()) * 3];
  return kernels::luminance(c);
}

// Active corner probes of `x`'s cell, split by whether a ray from `x` reaches them.
void split_corners(const DdgiResult& r, const PreparedScene& prepared, const std::array<float, 3>& x,
                   std::vector<int32_t>& near_side, std::vector<int32_t>& across) {
  const float3 from{x[0], x[1], x[2]};
  for (const CornerProbe& p : cell_corners(r, x)) {
    if (r.states[size_t(p.index)] == ProbeState::Inactive) continue;
    const float3 d = p.position - from;
    const float len = std::sqrt(kernels::dot(d, d));
    const bool blocked = len > 0.f && prepared.occluded(from, d * (1.f / len), 0.f, len);
    (blocked ? across : near_side).push_back(p.index);
  }
}

}  // namespace

std::vector<LeakExposure> leak_exposure(const LeakAudit& audit, const DdgiResult& probes,
                                        const PreparedScene& prepared) {
  std::vector<LeakExposure> out(audit.regions.size());
  if (probes.states.empty() || probes.offsets.size() < probes.states.size() * 3) return out;
  for (size_t i = 0; i < audit.regions.size(); ++i) {
    const LeakRegion& region = audit.regions[i];
    out[i].region = i;
    for (const auto& point : {region.dark_point, region.lit_point}) {
      std::vector<int32_t> near_side, across;
      split_corners(probes, prepared, point, near_side, across);
      // Blending across needs active probes on both sides: where the near side's are all inactive
      // (the inside of a closed box), nothing there is shaded from this side's light.
      if (near_side.empty() || across.empty()) continue;
      out[i].probes_across += int(across.size());
      float nearest = 0.f;
      for (int32_t n : near_side) nearest = std::max(nearest, dc_luminance(probes, n));
      for (int32_t a : across)
        out[i].radiance_across = std::max(out[i].radiance_across, std::fabs(dc_luminance(probes, a) - nearest));
    }
  }
  return out;
}

std::vector<LeakExposure> ranked_exposed(const std::vector<LeakExposure>& all) {
  std::vector<LeakExposure> out;
  for (const LeakExposure& e : all)
    if (e.probes_across > 0) out.push_back(e);
  std::stable_sort(out.begin(), out.end(), [](const LeakExposure& a, const LeakExposure& b) {
    return a.radiance_across > b.radiance_across;
  });
  return out;
}

}  // namespace gibake
