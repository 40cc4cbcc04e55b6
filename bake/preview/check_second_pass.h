// The reconstruction check's second pass (ReconstructionSettings::target_noise, --check-noise):
// which patches are traced again, and with how many paths a point. A patch whose reference's
// relative standard error e is above the target needs rays x (e / t)^2 paths a point to reach a
// noise t. t is the smallest noise, at least the target, whose second passes fit the budget: every
// point may spend `ray_budget` paths on average over both passes (0: default_budget_factor() times
// the first pass's), and a point at most 64 times the first pass's. The
// noisiest patches are so brought to one noise, as low as the budget allows. The second pass's paths
// replace the first's: a count chosen from the paths it weighs would bias the estimate.
#pragma once
#include <cstdint>
#include <vector>

namespace gibake {

// The default budget, in first passes. A device traces a patch's paths in microseconds, and a patch
// lit through gaps needs dozens of times the first pass to read within a few percent. On the CPU
// the check from the probes' view, which every bake runs, stays near its one-pass cost; a check
// from camera views is the one a user sets beside a picture, and the patches a view sees in shade
// (lit through arches and gaps) read a right bake as wrong until their references are about 3%
// noisy, so it takes the device's share.
constexpr uint32_t kDeviceBudgetFactor = 32, kCpuBudgetFactor = 4, kCpuViewBudgetFactor = 32;
inline uint32_t default_budget_factor(bool on_device, bool from_views) {
  return on_device ? kDeviceBudgetFactor : from_views ? kCpuViewBudgetFactor : kCpuBudgetFactor;
}

struct PatchNoise {
  double noise = 0.0;   // relative standard error of its reference (0: none, or no light)
  uint32_t points = 0;  // its points that met a visible surface
};

// Paths a point for each patch's second pass (0: none), for a first pass of `rays` paths a point;
// `default_factor`: the budget in first passes when `ray_budget` is 0 (default_budget_factor()).
std::vector<uint32_t> second_pass_rays(const std::vector<PatchNoise>& patches, uint32_t rays, float target_noise,
                                       uint32_t ray_budget, uint32_t default_factor);

}  // namespace gibake
