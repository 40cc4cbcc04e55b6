// Vulkan bakes at and past the sizes where a device's limits bind, each against the CPU bake of the
// same settings. Rays per probe around 2^15, 2^16 and at 2^18: Mesa's llvmpipe (lavapipe) ends every
// loop of an invocation after 65535 iterations, so a kernel whose loop walked all of a probe's rays
// (or, with the probe's emitter samples, twice as many samples) would lose rays there; the kernels walk
// windows of GPU_RAY_WINDOW (kernels/shaders/gpu_types.h). With the Cornell box's emitter (paired
// samples) and with a sky-lit floor (none). And a bake whose grids exceed a lowered
// maxComputeWorkGroupCount (vk::ContextOptions::max_group_count), folded into two dimensions. Each
// probe must trace the CPU's rays (the same count: a lost ray shows here) and its SH and irradiance
// texels must agree within 1e-3 of the bake's largest value (paths agree ray for ray up to float
// rounding, as in gpu_adaptive_test).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "io/gltf/import.h"
#include "tests/vulkan/gpu_test_scenes.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

std::string test_device() {
  const char* env = std::getenv("GIBAKE_TEST_VULKAN_DEVICE");
  return env && *env ? env : "lavapipe";
}

// `max_groups` > 0: a Vulkan bake under that maxComputeWorkGroupCount; 0 and `gpu`: the device's.
// `device_memory` > 0: as if the device had that much device-local memory.
Status bake(const Scene& scene, DdgiSettings s, bool gpu, DdgiResult& r, uint32_t max_groups = 0,
            uint64_t device_memory = 0) {
  if (gpu) {
    s.backend.backend = Backend::Vulkan;
    s.backend.vulkan_device = test_device();
    s.backend.validation = true;
    s.backend.vulkan_max_group_count = max_groups;
    s.backend.vulkan_device_memory = device_memory;
  }
  DdgiReport rep;
  return bake_ddgi(scene, s, Context{}, r, rep);
}

float largest_difference(const std::vector<float>& a, const std::vector<float>& b, float& peak) {
  peak = 0.f;
  float diff = 0.f;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    peak = std::max(peak, std::fabs(a[i]));
    diff = std::max(diff, std::fabs(a[i] - b[i]));
  }
  return diff;
}

void compare(const DdgiResult& cpu, const DdgiResult& gpu, const std::string& what) {
  ASSERT_EQ(cpu.stats.size(), gpu.stats.size()) << what;
  for (size_t p = 0; p < cpu.stats.size(); ++p) EXPECT_EQ(gpu.stats[p].rays, cpu.stats[p].rays) << what << " probe " << p;
  ASSERT_EQ(cpu.sh.size(), gpu.sh.size()) << what;
  ASSERT_EQ(cpu.irradiance_atlas.size(), gpu.irradiance_atlas.size()) << what;
  float sh_peak = 0.f, irr_peak = 0.f;
  const float sh = largest_difference(cpu.sh, gpu.sh, sh_peak);
  const float irr = largest_difference(cpu.irradiance_atlas, gpu.irradiance_atlas, irr_peak);
  ASSERT_GT(sh_peak, 0.f) << what;
  ASSERT_GT(irr_peak, 0.f) << what;
  EXPECT_LE(sh, 1e-3f * sh_peak) << what;
  EXPECT_LE(irr, 1e-3f * irr_peak) << what;
  std::printf("%s: %u rays a probe, SH within %.3g and irradiance within %.3g of the largest value\n", what.c_str(),
              cpu.stats[0].rays, sh / sh_peak, irr / irr_peak);
}

bool have_device() {
  std::string why;
  return !test::vulkan_missing(why);
}

void matches_cpu_at(const Scene& scene, DdgiSettings s, std::initializer_list<uint32_t> ray_counts, const char* what) {
  for (uint32_t rays : ray_counts) {
    s.rays = rays;
    DdgiResult cpu, gpu;
    ASSERT_TRUE(bake(scene, s, false, cpu).is_ok());
    const Status st = bake(scene, s, true, gpu);
    ASSERT_TRUE(st.is_ok()) << st.message();
    for (const DdgiProbeStats& probe : cpu.stats) ASSERT_EQ(probe.rays, rays);
    compare(cpu, gpu, std::string(what) + ", " + std::to_string(rays) + " rays");
  }
}

DdgiSettings one_probe() {
  DdgiSettings s;
  s.grid.counts = {1, 1, 1};
  s.bounces = 0;  // direct light and the emitter samples: the windows are the same, the paths cheap
  s.relocate = false;
  return s;
}

Scene cornell() {
  Scene scene;
  EXPECT_TRUE(
      import_scene(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf", {}, Context{}, scene).is_ok());
  return scene;
}

DdgiSettings floor_probe() {
  DdgiSettings s = test::floor_and_wall_grid(1);
  s.grid.counts = {1, 1, 1};  // the grid's centre, 1 m over the floor
  s.bounces = 0;
  s.relocate = false;
  return s;
}

// Each case its own test, so that ctest runs them side by side. With the emitter samples, a probe
// of 32,768 rays has 65,536 samples.
TEST(VulkanLimits, CornellWithEmitterSamplesAround32768Rays) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  matches_cpu_at(cornell(), one_probe(), {32767u, 32768u}, "cornell, emitter samples");
}
TEST(VulkanLimits, CornellWithEmitterSamplesAround65536Rays) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  matches_cpu_at(cornell(), one_probe(), {65535u, 65536u}, "cornell, emitter samples");
}
TEST(VulkanLimits, CornellWithEmitterSamplesAt262144Rays) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  matches_cpu_at(cornell(), one_probe(), {262144u}, "cornell, emitter samples");
}
TEST(VulkanLimits, SkyLitFloorAround32768Rays) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  matches_cpu_at(test::floor_and_wall(), floor_probe(), {32767u, 32768u}, "floor and wall, no emitter samples");
}
TEST(VulkanLimits, SkyLitFloorAround65536Rays) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  matches_cpu_at(test::floor_and_wall(), floor_probe(), {65535u, 65536u}, "floor and wall, no emitter samples");
}
TEST(VulkanLimits, SkyLitFloorAt262144Rays) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  matches_cpu_at(test::floor_and_wall(), floor_probe(), {262144u}, "floor and wall, no emitter samples");
}

// Every 1-D grid of the bake (ray generation, paths, statistics, relocation) folded into rows of 64
// workgroups: a path batch of 2^17 rays is 2048 groups, 32 rows.
TEST(VulkanLimits, GridsPastTheGroupCountFoldIntoRows) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  DdgiSettings s = one_probe();
  s.grid.counts = {2, 1, 1};
  s.rays = 65536;
  s.bounces = 1;
  s.relocate = true;  // relocation's sums too
  DdgiResult cpu, gpu;
  const Scene scene = cornell();
  ASSERT_TRUE(bake(scene, s, false, cpu).is_ok());
  const Status st = bake(scene, s, true, gpu, 64);
  ASSERT_TRUE(st.is_ok()) << st.message();
  compare(cpu, gpu, "cornell, 64 workgroups a row");
}

// Device memory: the scene's buffers and one ray batch must fit the device's memory (here a test
// limit far below lavapipe's heap); the batch shrinks to fit, the scene cannot. Under a limit the
// scene fits with only small batches, the bake traces what the CPU traces; under one the scene
// itself exceeds, the bake is refused before its first ray in one line naming the figure, the
// device's memory and the way out.
TEST(VulkanLimits, RaysBatchesShrinkToTheDeviceMemory) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  DdgiSettings s = one_probe();
  s.grid.counts = {2, 2, 2};
  s.rays = 4096;
  s.bounces = 2;
  DdgiResult cpu, gpu;
  const Scene scene = cornell();
  ASSERT_TRUE(bake(scene, s, false, cpu).is_ok());
  // lavapipe's path batch of 2^19 rays takes more than 48 MiB: the limit leaves it a quarter or less.
  const Status st = bake(scene, s, true, gpu, 0, uint64_t(48) << 20);
  ASSERT_TRUE(st.is_ok()) << st.message();
  compare(cpu, gpu, "cornell, 48 MiB of device memory");
}

TEST(VulkanLimits, ASceneOverTheDeviceMemoryIsRefusedNamingTheFigure) {
  if (!have_device()) GTEST_SKIP() << "no Vulkan device";
  DdgiSettings s = one_probe();
  DdgiResult gpu;
  const Status st = bake(cornell(), s, true, gpu, 0, uint64_t(16) << 10);
  ASSERT_FALSE(st.is_ok());
  EXPECT_EQ(st.code(), ExitCode::RuntimeFailure);
  const std::string m = st.message();
  std::printf("refused: %s\n", m.c_str());
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_NE(m.find("of device memory"), std::string::npos) << m;
  EXPECT_NE(m.find(" has 16 KiB (test limit)"), std::string::npos) << m;
  EXPECT_NE(m.find("--backend cpu"), std::string::npos) << m;
  EXPECT_TRUE(gpu.stats.empty() || gpu.stats[0].rays == 0) << "traced before the refusal";
}

}  // namespace
}  // namespace gibake
