// LPV propagation on lavapipe against the CPU's lpv_propagate_volume: the same accumulated volume
// within float tolerance (the sums run in the same order; only rounding of dot products and fused
// multiply-adds differs): every coefficient within 1e-5 x the largest |coefficient| + 1e-5 x its own.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bake/lpv/lpv.h"
#include "bake/vulkan/lpv.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

void compare(bool occlusion, int iterations) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  kernels::LpvGrid grid;
  grid.dims[0] = 12;
  grid.dims[1] = 9;
  grid.dims[2] = 10;
  grid.origin_cell[3] = 0.5f;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  std::vector<kernels::LpvCell> cells(grid.cells());
  for (size_t i = 0; i < cells.size(); i += 7)  // sparse sources, light in every direction
    for (int ch = 0; ch < 3; ++ch) {
      const float c0 = 10.f * u01(rng);
      cells[i].sh[ch][0] = c0;
      for (int k = 1; k < 4; ++k) cells[i].sh[ch][k] = c0 * (u01(rng) - 0.5f);
    }
  std::vector<float> geometry;
  if (occlusion) {
    geometry.assign(size_t(grid.dims[0] + 1) * (grid.dims[1] + 1) * (grid.dims[2] + 1) * 4, 0.f);
    for (size_t i = 0; i < geometry.size() / 4; i += 3) {
      geometry[i * 4] = 2.f * u01(rng);
      for (int k = 1; k < 4; ++k) geometry[i * 4 + k] = 2.f * (u01(rng) - 0.5f);
    }
  }
  std::vector<kernels::LpvCell> cpu, gpu;
  ASSERT_TRUE(lpv_propagate_volume(grid, cells, occlusion ? geometry.data() : nullptr, iterations, Context{}, cpu));
  const Status st = lpv_propagate_volume_gpu(*vk, grid, cells, occlusion ? geometry.data() : nullptr, iterations, gpu);
  ASSERT_TRUE(st) << st.message();
  ASSERT_EQ(gpu.size(), cpu.size());
  float peak = 0.f;
  for (const auto& c : cpu)
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 0; k < 4; ++k) peak = std::max(peak, std::fabs(c.sh[ch][k]));
  ASSERT_GT(peak, 0.f);
  size_t bad = 0;
  float worst = 0.f;
  for (size_t i = 0; i < cpu.size(); ++i)
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 0; k < 4; ++k) {
        const float d = std::fabs(gpu[i].sh[ch][k] - cpu[i].sh[ch][k]);
        worst = std::max(worst, d / peak);
        if (d > 1e-5f * peak + 1e-5f * std::fabs(cpu[i].sh[ch][k])) ++bad;
      }
  EXPECT_EQ(bad, 0u) << "worst difference " << worst << " of the peak";
  // Light spread: cells far from any source received some (the propagation really ran).
  EXPECT_GT(cpu[grid.index(11, 8, 9)].sh[0][0] + cpu[grid.index(0, 0, 0)].sh[0][0], 0.f);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

TEST(GpuLpv, PropagationMatchesCpuOpen) { compare(false, 12); }
TEST(GpuLpv, PropagationMatchesCpuOccluded) { compare(true, 12); }

}  // namespace
}  // namespace gibake
