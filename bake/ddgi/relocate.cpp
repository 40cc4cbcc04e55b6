#include "bake/ddgi/relocate.h"

#include <algorithm>
#include <cmath>

namespace gibake {

RelocationSums relocation_sums(const kernels::HitRecord* hits, uint32_t count, float threshold) {
  RelocationSums s;
  s.nearest = threshold;
  for (uint32_t r = 0; r < count; ++r) {
    const kernels::HitRecord& h = hits[r];
    if (h.kind() != kernels::kHitFront) continue;
    const float depth = h.dir_t[3];
    if (depth >= threshold) continue;
    s.close = true;
    s.nearest = std::min(s.nearest, depth);
    for (int a = 0; a < 3; ++a) s.delta[a] -= double(h.dir_t[a]) * (threshold - depth);
  }
  return s;
}

bool apply_relocation(const RelocationSums& s, const RelocateParams& params, std::array<float, 3>& offset) {
  if (params.threshold <= 0.f || !s.close) return false;
  const double* delta = s.delta;
  const double len = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
  if (len <= 0.0) return false;
  const double step = double(params.threshold) - s.nearest;
  for (int a = 0; a < 3; ++a) {
    const float m = params.max_offset[a];
    offset[a] = std::clamp(static_cast<float>(offset[a] + delta[a] / len * step), -m, m);
  }
  return true;
}

}  // namespace gibake
