// The backend switch's choice for made-up device lists (no Vulkan needed).
#include <gtest/gtest.h>

#include "bake/run/backend.h"

namespace gibake {
namespace {

vk::DeviceInfo dev(uint32_t index, const char* name, const char* type) {
  vk::DeviceInfo d;
  d.index = index;
  d.name = name;
  d.type = type;
  d.driver = std::string(type) == "cpu" ? "llvmpipe" : "NVIDIA 550";
  d.compute = true;
  return d;
}

const std::vector<vk::DeviceInfo> kLavapipeOnly = {dev(0, "llvmpipe (LLVM 15.0.6, 256 bits)", "cpu")};
const std::vector<vk::DeviceInfo> kBoth = {dev(0, "llvmpipe (LLVM 15.0.6, 256 bits)", "cpu"),
                                           dev(1, "Intel(R) UHD Graphics", "integrated"),
                                           dev(2, "NVIDIA H100 PCIe", "discrete")};

TEST(Backend, CpuNeverTouchesDevices) {
  BackendChoice c;
  ASSERT_TRUE(choose_backend({Backend::Cpu, "", false}, kBoth, c));
  EXPECT_EQ(c.backend, Backend::Cpu);
}

// A bake heavy enough for either GPU (80,640 probes x 2,048 rays on 4 threads: the cost model's
// cases are in backend_cost_test.cpp); without a workload auto takes the CPU.
TEST(Backend, AutoPrefersDiscreteThenIntegratedNeverLavapipe) {
  BackendSettings s{Backend::Auto, "", false};
  s.workload.probes = 80640;
  s.workload.rays = 2048;
  s.workload.bounces = 4;
  s.workload.threads = 4;
  BackendChoice c;
  ASSERT_TRUE(choose_backend(s, kBoth, c));
  EXPECT_EQ(c.backend, Backend::Vulkan);
  EXPECT_EQ(c.device.index, 2u);
  ASSERT_TRUE(choose_backend(s, {kBoth[0], kBoth[1]}, c));
  EXPECT_EQ(c.device.index, 1u);
  ASSERT_TRUE(choose_backend(s, kLavapipeOnly, c));
  EXPECT_EQ(c.backend, Backend::Cpu);
  ASSERT_TRUE(choose_backend(s, {}, c));
  EXPECT_EQ(c.backend, Backend::Cpu);
  ASSERT_TRUE(choose_backend({Backend::Auto, "", false}, kBoth, c));
  EXPECT_EQ(c.backend, Backend::Cpu);
  // A named GPU is auto's candidate; a named lavapipe never is (--backend vulkan runs on it).
  s.vulkan_device = "1";
  ASSERT_TRUE(choose_backend(s, kBoth, c));
  EXPECT_EQ(c.device.index, 1u);
  s.vulkan_device = "lavapipe";
  ASSERT_TRUE(choose_backend(s, kBoth, c));
  EXPECT_EQ(c.backend, Backend::Cpu);
}

TEST(Backend, VulkanWithoutGpuIsRuntimeFailure) {
  BackendChoice c;
  const Status st = choose_backend({Backend::Vulkan, "", false}, kLavapipeOnly, c);
  EXPECT_EQ(st.code(), ExitCode::RuntimeFailure);
  EXPECT_NE(st.message().find("--vulkan-device"), std::string::npos) << st.message();
  EXPECT_EQ(choose_backend({Backend::Vulkan, "", false}, {}, c).code(), ExitCode::RuntimeFailure);
}

TEST(Backend, NamedDevices) {
  BackendChoice c;
  ASSERT_TRUE(choose_backend({Backend::Vulkan, "lavapipe", false}, kBoth, c));
  EXPECT_EQ(c.device.index, 0u);
  ASSERT_TRUE(choose_backend({Backend::Vulkan, "1", false}, kBoth, c));
  EXPECT_EQ(c.device.index, 1u);
  ASSERT_TRUE(choose_backend({Backend::Vulkan, "h100", false}, kBoth, c));
  EXPECT_EQ(c.device.index, 2u);
  EXPECT_EQ(choose_backend({Backend::Vulkan, "7", false}, kBoth, c).code(), ExitCode::RuntimeFailure);
  EXPECT_EQ(choose_backend({Backend::Vulkan, "radeon", false}, kBoth, c).code(), ExitCode::RuntimeFailure);
  EXPECT_EQ(choose_backend({Backend::Vulkan, "lavapipe", false}, {kBoth[2]}, c).code(), ExitCode::RuntimeFailure);
}

TEST(Backend, Names) {
  Backend b;
  for (Backend x : {Backend::Auto, Backend::Cpu, Backend::Vulkan}) {
    ASSERT_TRUE(parse_backend(backend_name(x), b));
    EXPECT_EQ(b, x);
  }
  EXPECT_FALSE(parse_backend("gpu", b));
}

}  // namespace
}  // namespace gibake
