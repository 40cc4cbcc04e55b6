// For the Vulkan twins of the bake suites: every test is skipped, with the reason, when lavapipe
// (or GIBAKE_TEST_VULKAN_DEVICE) does not open.
#include <gtest/gtest.h>

#include "tests/vulkan/vulkan_test_util.h"

namespace {
class VulkanEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    std::unique_ptr<gibake::vk::Context> ctx;
    const std::string why = gibake::test::open_test_device(ctx);
    if (!why.empty()) GTEST_SKIP() << "no Vulkan device for the Vulkan bake tests: " << why;
  }
};
const auto* const kEnv = ::testing::AddGlobalTestEnvironment(new VulkanEnvironment);
}  // namespace

#include "bake/pipeline/devices.h"
#include "tests/bake/scene_builders.h"
#include "tests/bake/test_backend.h"

// The twin suites really bake on the device: the bake file's settings say so.
TEST(VulkanTwin, BakesOnTheDevice) {
  using namespace gibake;
  Scene scene;
  test::add_box(scene, {0, 0, 0}, {1, 1, 1}, true, test::add_material(scene, 0.5f, 1.f));
  DdgiSettings s;
  s.grid.explicit_bounds = true;
  s.grid.grid_min = s.grid.grid_max = {0.5f, 0.5f, 0.5f};
  s.grid.counts = {1, 1, 1};
  s.rays = 64;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, test::on_test_backend(s), Context{}, r, rep));
  EXPECT_NE(r.settings_json.find("\"backend\":\"vulkan\""), std::string::npos) << r.settings_json;
  EXPECT_GT(rep.bounce_rays, 0u);
}
