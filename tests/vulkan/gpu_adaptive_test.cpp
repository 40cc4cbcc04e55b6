// --target-error on the Vulkan device (bake/vulkan/ddgi_device.cpp, device passes): each probe's
// statistics continue on the device pass after pass and its integrals accumulate there; the host
// reads 48 bytes a probe per pass and makes the stop decision (ProbeBatches::unfinished) from the
// device's Welford state. Against the CPU bake of the same settings: the same rays per probe (the
// same stop decisions: the device's statistics are the CPU's doubles on lavapipe, tests/vulkan/
// gpu_probe_stats_test.cpp), the same probe states, SH within 1e-3 of the bake's largest |SH|
// (paths agree ray for ray up to float rounding; the test prints the largest difference), and two
// device bakes byte for byte alike. With and without the probe's emitter samples (paired), in one
// chunk and in many small chunks in flight; the host route (no doubles: per-ray outputs kept as
// records on the host) gives the same rays per probe and the same statistics to the bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

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

enum class Route { Cpu, Device, DeviceSmallChunks, DeviceOneBlockGroups, HostRecords };

Status bake(const Scene& scene, DdgiSettings s, Route route, DdgiResult& r, std::string* notes = nullptr) {
  if (route != Route::Cpu) {
    s.backend.backend = Backend::Vulkan;
    s.backend.vulkan_device = test_device();
    s.backend.validation = true;
    s.backend.float64 = route != Route::HostRecords;
    if (route == Route::DeviceSmallChunks) {
      s.backend.vulkan_in_flight = 3;
      s.backend.vulkan_chunk_rays = 5 * s.rays;  // five probes a chunk
    }
    // Passes in groups of one block each, as a volume whose accumulators pass one buffer runs.
    if (route == Route::DeviceOneBlockGroups) s.backend.vulkan_pass_group_probes = 512;
  }
  DdgiReport rep;
  Context ctx;
  std::string collected;
  ctx.info = [&](const std::string& line) { collected += line + "\n"; };
  const Status st = bake_ddgi(scene, s, ctx, r, rep);
  if (notes) *notes = collected;
  return st;
}

// `same_paths`: both bakes traced on the device (the same path outputs), so the statistics the host
// reduced from them equal those the device did, to the bit (lavapipe rounds doubles correctly).
void compare(const DdgiResult& cpu, const DdgiResult& gpu, const char* what, bool same_paths = false) {
  ASSERT_EQ(cpu.stats.size(), gpu.stats.size());
  uint32_t lo = ~0u, hi = 0;
  for (size_t p = 0; p < cpu.stats.size(); ++p) {
    EXPECT_EQ(gpu.stats[p].rays, cpu.stats[p].rays) << what << " probe " << p;
    if (same_paths) {
      EXPECT_EQ(gpu.stats[p].relative_error, cpu.stats[p].relative_error) << what << " probe " << p;
      EXPECT_EQ(gpu.stats[p].nearest_front, cpu.stats[p].nearest_front) << what << " probe " << p;
      EXPECT_EQ(gpu.stats[p].backface_fraction, cpu.stats[p].backface_fraction) << what << " probe " << p;
    }
    lo = std::min(lo, cpu.stats[p].rays);
    hi = std::max(hi, cpu.stats[p].rays);
  }
  EXPECT_LT(lo, hi) << what << ": the probes should stop after different passes";
  EXPECT_EQ(gpu.states, cpu.states) << what;
  ASSERT_EQ(gpu.sh.size(), cpu.sh.size());
  float peak = 0.f, diff = 0.f;
  for (size_t i = 0; i < cpu.sh.size(); ++i) {
    peak = std::max(peak, std::fabs(cpu.sh[i]));
    diff = std::max(diff, std::fabs(cpu.sh[i] - gpu.sh[i]));
  }
  ASSERT_GT(peak, 0.f);
  EXPECT_LE(diff, 1e-3f * peak) << what;
  std::printf("%s: rays per probe %u..%u, SH within %.3g of the largest |SH| %.3g\n", what, lo, hi, diff / peak, peak);
}

void run(const Scene& scene, const DdgiSettings& s, const char* what) {
  std::unique_ptr<vk::Context> probe;
  GIBAKE_OPEN_VULKAN_OR_SKIP(probe);
  if (!probe->shader_float64()) GTEST_SKIP() << "the test device has no doubles: no device passes";
  probe.reset();
  DdgiResult cpu, gpu, again, small, host;
  std::string notes;
  ASSERT_TRUE(bake(scene, s, Route::Cpu, cpu).is_ok());
  ASSERT_TRUE(bake(scene, s, Route::Device, gpu, &notes).is_ok());
  EXPECT_NE(notes.find("vulkan: adaptive rays on the device"), std::string::npos) << notes;
  compare(cpu, gpu, what);
  ASSERT_TRUE(bake(scene, s, Route::Device, again).is_ok());
  EXPECT_EQ(gpu.sh, again.sh);
  EXPECT_EQ(gpu.irradiance_atlas, again.irradiance_atlas);
  EXPECT_EQ(gpu.depth_atlas, again.depth_atlas);
  // Chunks in flight only regroup the same work: the same bytes.
  ASSERT_TRUE(bake(scene, s, Route::DeviceSmallChunks, small).is_ok());
  EXPECT_EQ(gpu.sh, small.sh);
  EXPECT_EQ(gpu.irradiance_atlas, small.irradiance_atlas);
  EXPECT_EQ(gpu.depth_atlas, small.depth_atlas);
  ASSERT_TRUE(bake(scene, s, Route::HostRecords, host, &notes).is_ok());
  EXPECT_EQ(notes.find("vulkan: adaptive rays on the device"), std::string::npos) << notes;
  EXPECT_NE(notes.find("vulkan: adaptive rays with per-ray records on the host between passes"), std::string::npos)
      << notes;
  EXPECT_NE(notes.find("no 64-bit floats (shaderFloat64)"), std::string::npos) << notes;
  compare(host, gpu, "host records vs device passes", true);
}

TEST(VulkanAdaptive, CornellWithEmitterSamplesMatchesCpu) {
  Scene scene;
  ASSERT_TRUE(
      import_scene(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf", {}, Context{}, scene).is_ok());
  DdgiSettings s;
  s.rays = 32;
  s.max_rays = 512;
  s.target_error = 0.1f;
  s.bounces = 2;
  s.grid.counts = {4, 4, 4};
  run(scene, s, "cornell, emitter samples");
}

TEST(VulkanAdaptive, SkyLitFloorMatchesCpu) {
  const Scene scene = test::floor_and_wall();
  DdgiSettings s = test::floor_and_wall_grid(16);
  s.max_rays = 256;
  s.target_error = 0.05f;
  s.bounces = 1;
  run(scene, s, "floor and wall, no emitter samples");
}

// The ray budget, decided per block of 512 probes (bake/ddgi/trace_batches.h) from the device's
// statistics as from the CPU's: two blocks (576 probes), a budget that binds in both (the CPU bound
// itself: tests/bake/path_gather_test.cpp), the same rays per probe and states as the CPU bake; and
// the device's passes run a block at a time (DdgiDevice::pass_group_probes) give the same bytes.
TEST(VulkanAdaptive, BlockRayBudgetMatchesCpu) {
  std::unique_ptr<vk::Context> probe;
  GIBAKE_OPEN_VULKAN_OR_SKIP(probe);
  if (!probe->shader_float64()) GTEST_SKIP() << "the test device has no doubles: no device passes";
  probe.reset();
  Scene scene;
  ASSERT_TRUE(
      import_scene(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf", {}, Context{}, scene).is_ok());
  DdgiSettings s;
  s.rays = 16;
  s.max_rays = 256;
  s.target_error = 0.02f;
  s.bounces = 1;
  s.grid.counts = {9, 8, 8};
  DdgiResult unbounded, cpu, gpu;
  ASSERT_TRUE(bake(scene, s, Route::Cpu, unbounded).is_ok());
  s.ray_budget = 48;
  ASSERT_TRUE(bake(scene, s, Route::Cpu, cpu).is_ok());
  ASSERT_TRUE(bake(scene, s, Route::Device, gpu).is_ok());
  // The budget binds in each block: without it, each block's probes get more rays.
  for (size_t first : {size_t(0), size_t(512)}) {
    const size_t last = std::min(cpu.stats.size(), first + 512);
    uint64_t spent = 0, unbudgeted = 0;
    for (size_t p = first; p < last; ++p) spent += cpu.stats[p].rays, unbudgeted += unbounded.stats[p].rays;
    EXPECT_LT(spent, unbudgeted) << "block at " << first << ": the budget must bind";
  }
  compare(cpu, gpu, "cornell, block ray budget");
  // The device's passes in two groups (one block each), one after the other: the same bytes.
  DdgiResult grouped;
  std::string notes;
  ASSERT_TRUE(bake(scene, s, Route::DeviceOneBlockGroups, grouped, &notes).is_ok());
  EXPECT_NE(notes.find("vulkan: adaptive rays on the device"), std::string::npos) << notes;
  EXPECT_NE(notes.find("trace: adaptive passes in 2 groups of up to 512 probes"), std::string::npos) << notes;
  EXPECT_EQ(gpu.sh, grouped.sh);
  EXPECT_EQ(gpu.irradiance_atlas, grouped.irradiance_atlas);
  EXPECT_EQ(gpu.depth_atlas, grouped.depth_atlas);
  EXPECT_EQ(gpu.states, grouped.states);
  for (size_t p = 0; p < gpu.stats.size(); ++p) EXPECT_EQ(gpu.stats[p].rays, grouped.stats[p].rays) << "probe " << p;
}

// A volume traced only near surfaces (DdgiSettings::near_surface_reach): the device traces the
// probes the host's test kept, and the budget is shared by those alone, as on the CPU. 5 x 9 x 5
// probes 0.5 m apart over the floor beside the wall (x = 1.1): with a reach of 0.9 m those at x <= 0
// and 1 m or more above the floor have no surface near, 3 x 7 x 5 of them.
TEST(VulkanAdaptive, NearSurfaceVolumeMatchesCpu) {
  std::unique_ptr<vk::Context> probe;
  GIBAKE_OPEN_VULKAN_OR_SKIP(probe);
  if (!probe->shader_float64()) GTEST_SKIP() << "the test device has no doubles: no device passes";
  probe.reset();
  const Scene scene = test::floor_and_wall();
  DdgiSettings s = test::floor_and_wall_grid(16);
  s.grid.grid_max = {1, 4.01f, 1};
  s.grid.counts = {5, 9, 5};
  s.max_rays = 256;
  s.target_error = 0.02f;
  s.ray_budget = 48;
  s.bounces = 1;
  s.near_surface_reach = 0.9f;
  s.relocate = false;  // a probe's rays are then its trace's alone
  DdgiResult cpu, gpu;
  ASSERT_TRUE(bake(scene, s, Route::Cpu, cpu).is_ok());
  ASSERT_TRUE(bake(scene, s, Route::Device, gpu).is_ok());
  uint32_t left_out = 0;
  for (int32_t p = 0; p < 5 * 9 * 5; ++p) {
    const int32_t x = p % 5, y = p / 5 % 9;
    const bool far = x <= 2 && y >= 2;
    left_out += far;
    EXPECT_EQ(cpu.stats[size_t(p)].rays == 0, far) << "probe " << p;
    if (far) {
      EXPECT_EQ(cpu.states[size_t(p)], ProbeState::Inactive) << "probe " << p;
    }
  }
  EXPECT_EQ(left_out, 105u);
  // The block's budget is the traced probes' alone: the left-out ones lend it none.
  uint64_t spent = 0;
  for (const DdgiProbeStats& st : cpu.stats) spent += st.rays;
  EXPECT_LE(spent, uint64_t(s.ray_budget) * (5 * 9 * 5 - left_out));
  compare(cpu, gpu, "floor and wall, near surfaces only");
}

}  // namespace
}  // namespace gibake
