// Shared by the Vulkan tests: a context on Mesa's lavapipe (the device CI has), with the Khronos
// validation layer when installed. No Vulkan device at all: the test is skipped, saying why.
#pragma once
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "bake/run/backend.h"
#include "kernels/vulkan/context.h"

namespace gibake::test {

// Opens lavapipe (or, when GIBAKE_TEST_VULKAN_DEVICE is set, that device). Returns an empty
// string and a context, or why no device could be opened. `max_groups` > 0: a lower
// maxComputeWorkGroupCount[0] than the device's (vk::ContextOptions::max_group_count).
inline std::string open_test_device(std::unique_ptr<vk::Context>& out, uint32_t max_groups = 0) {
  BackendSettings s;
  s.backend = Backend::Vulkan;
  const char* env = std::getenv("GIBAKE_TEST_VULKAN_DEVICE");
  s.vulkan_device = env && *env ? env : "lavapipe";
  BackendChoice choice;
  Status st = resolve_backend(s, choice);
  if (!st) return st.message();
  s.validation = true;
  s.vulkan_max_group_count = max_groups;
  st = open_vulkan(choice, s, out);
  if (!st) return st.message();
  return "";
}

// True (and why) when no Vulkan device opens; for tests that open their own device later.
inline bool vulkan_missing(std::string& why) {
  std::unique_ptr<vk::Context> ctx;
  why = open_test_device(ctx);
  return !why.empty();
}

}  // namespace gibake::test

// Skips the test (with the reason) when no Vulkan device opens; `ctx` is a unique_ptr<vk::Context>.
#define GIBAKE_OPEN_VULKAN_OR_SKIP(ctx)                                                          \
  do {                                                                                           \
    const std::string why_ = ::gibake::test::open_test_device(ctx);                              \
    if (!why_.empty()) GTEST_SKIP() << "no Vulkan device for this test (install mesa-vulkan-drivers " \
                                       "for lavapipe): " << why_;                                \
  } while (0)

// After a test's GPU work: the validation layer (when on) reported no error.
#define GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx)                                                  \
  EXPECT_EQ((ctx)->validation_errors(), 0u) << (ctx)->first_validation_error()
