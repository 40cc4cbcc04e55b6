#include "bake/relocate.h"

#include <algorithm>
#include <cmath>

namespace gibake {

bool relocate_probe(const kernels::HitRecord* hits, uint32_t count, const RelocateParams& params,
                    std::array<float, 3>& offset) {
  if (params.threshold <= 0.f) return false;
  double delta[3] = {0, 0, 0};
  bool close = false;
  float nearest = params.threshold;
  for (uint32_t r = 0; r < count; ++r) {
    const kernels::HitRecord& h = hits[r];
    if (h.kind() != kernels::kHitFront) continue;
    const float depth = h.dir_t[3];
    if (depth >= params.threshold) continue;
    close = true;
    nearest = std::min(nearest, depth);
    for (int a = 0; a < 3; ++a) delta[a] -= double(h.dir_t[a]) * (params.threshold - depth);
  }
  if (!close) return false;
  const double len = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
  if (len <= 0.0) return false;
  const double step = double(params.threshold) - nearest;
  for (int a = 0; a < 3; ++a) {
    const float m = params.max_offset[a];
    offset[a] = std::clamp(static_cast<float>(offset[a] + delta[a] / len * step), -m, m);
  }
  return true;
}

}  // namespace gibake
