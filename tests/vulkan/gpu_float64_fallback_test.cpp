// A device without shaderFloat64 takes the routes of before: relocation rays and hits cross the
// bus and are reduced on the host, and the path gather downloads a brief per ray for the host's
// statistics. Lavapipe has doubles, so BackendSettings::float64 = false makes it act as such a
// device; both routes must give the bake the device reductions give, byte for byte (on lavapipe the
// reductions are bit-identical to the host's sums, tests/vulkan/gpu_reloc_sums_test.cpp and
// gpu_probe_stats_test.cpp).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "io/gltf/import.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

std::string test_device() {
  const char* env = std::getenv("GIBAKE_TEST_VULKAN_DEVICE");
  return env && *env ? env : "lavapipe";
}

Status bake_on_device(const Scene& scene, bool float64, DdgiResult& r) {
  DdgiSettings s;
  s.backend.backend = Backend::Vulkan;
  s.backend.vulkan_device = test_device();
  s.backend.validation = true;
  s.backend.float64 = float64;
  s.rays = 64;
  s.bounces = 2;
  s.grid.counts = {4, 4, 4};
  DdgiReport rep;
  return bake_ddgi(scene, s, Context{}, r, rep);
}

TEST(VulkanFallback, NoDoublesGivesTheSameBake) {
  std::unique_ptr<vk::Context> probe;
  GIBAKE_OPEN_VULKAN_OR_SKIP(probe);
  if (!probe->shader_float64()) GTEST_SKIP() << "the test device has no doubles: it takes the fallback anyway";
  probe.reset();
  Scene scene;
  ASSERT_TRUE(
      import_scene(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf", {}, Context{}, scene).is_ok());
  DdgiResult with, without;
  ASSERT_TRUE(bake_on_device(scene, true, with).is_ok());
  ASSERT_TRUE(bake_on_device(scene, false, without).is_ok());
  EXPECT_EQ(with.offsets, without.offsets);
  EXPECT_EQ(with.states, without.states);
  EXPECT_EQ(with.sh, without.sh);
  EXPECT_EQ(with.irradiance_atlas, without.irradiance_atlas);
  EXPECT_EQ(with.depth_atlas, without.depth_atlas);
  ASSERT_EQ(with.stats.size(), without.stats.size());
  size_t moved = 0;
  for (size_t p = 0; p < with.stats.size(); ++p) {
    EXPECT_EQ(with.stats[p].rays, without.stats[p].rays) << p;
    EXPECT_EQ(with.stats[p].relative_error, without.stats[p].relative_error) << p;
    EXPECT_EQ(with.stats[p].backface_fraction, without.stats[p].backface_fraction) << p;
    EXPECT_EQ(with.stats[p].nearest_front, without.stats[p].nearest_front) << p;
    moved += with.offsets[p * 3] != 0.f || with.offsets[p * 3 + 1] != 0.f || with.offsets[p * 3 + 2] != 0.f;
  }
  EXPECT_GT(moved, 0u) << "the grid should relocate some probes, or the relocation routes are not compared";
}

}  // namespace
}  // namespace gibake
