// The reconstruction check's second pass (ReconstructionSettings::target_noise, --check-noise):
// which patches are traced again, and with how many paths a point. A patch whose reference's
// relative standard error e is above the target needs rays x (e / t)^2 paths a point to reach a
// noise t. t is the smallest noise, at least the target, whose second passes fit the budget: every
// point may spend `ray_budget` paths on average over both passes (0: kDeviceBudgetFactor or
// kCpuBudgetFactor times the first pass's), and a point at most 64 times the first pass's. The
// noisiest patches are so brought to one noise, as low as the budget allows. The second pass's paths
// replace the first's: a count chosen from the paths it weighs would bias the estimate.
#pragma once
#include <cstdint>
#include <vector>

namespace gibake {

// The default budget, in first passes: a device traces a patch's paths in microseconds, and a patch
// lit through gaps needs dozens of times the first pass to read within a few percent; the CPU keeps
// the check near its one-pass cost.
constexpr uint32_t kDeviceBudgetFactor = 32, kCpuBudgetFactor = 4;

struct PatchNoise {
  double noise = 0.0;   // relative standard error of its reference (0: none, or no light)
  uint32_t points = 0;  // its points that met a visible surface
};

// Paths a point for each patch's second pass (0: none), for a first pass of `rays` paths a point;
// `on_device`: the paths are traced on a device (the larger default budget).
std::vector<uint32_t> second_pass_rays(const std::vector<PatchNoise>& patches, uint32_t rays, float target_noise,
                                       uint32_t ray_budget, bool on_device);

}  // namespace gibake
