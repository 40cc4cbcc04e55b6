// The reconstruction check's second pass (check_second_pass.h).
#include "bake/preview/check_second_pass.h"

#include <algorithm>
#include <cmath>

namespace gibake {

std::vector<uint32_t> second_pass_rays(const std::vector<PatchNoise>& patches, uint32_t rays, float target_noise,
                                       uint32_t ray_budget, uint32_t default_factor) {
  std::vector<uint32_t> out(patches.size(), 0);
  const uint64_t budget_rays = ray_budget ? ray_budget : uint64_t(rays) * default_factor;
  if (!(target_noise > 0.f) || rays == 0 || budget_rays <= rays) return out;
  uint64_t points = 0;
  double largest = 0.0;
  for (const PatchNoise& p : patches) {
    points += p.points;
    if (std::isfinite(p.noise)) largest = std::max(largest, p.noise);
  }
  const double cap = std::min(double(1u << 16), 64.0 * rays);
  auto rays_at = [&](const PatchNoise& p, double t) {
    return std::isfinite(p.noise) && p.noise > t ? std::min(cap, std::ceil(rays * (p.noise / t) * (p.noise / t))) : 0.0;
  };
  auto spent = [&](double t) {
    double sum = 0.0;
    for (const PatchNoise& p : patches) sum += rays_at(p, t) * double(p.points);
    return sum;
  };
  const double extra = double(points) * double(budget_rays - rays);
  double lo = target_noise, hi = std::max(largest, lo);
  if (spent(lo) > extra) {
    for (int it = 0; it < 50; ++it) {  // spent falls as t rises: the smallest t that fits
      const double mid = 0.5 * (lo + hi);
      (spent(mid) > extra ? lo : hi) = mid;
    }
    lo = hi;
  }
  for (size_t i = 0; i < patches.size(); ++i) out[i] = uint32_t(rays_at(patches[i], lo));
  return out;
}

}  // namespace gibake
