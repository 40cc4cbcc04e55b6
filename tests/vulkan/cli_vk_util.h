// Shared by the Vulkan CLI tests: the sample scene, scratch paths and which devices are present.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "kernels/vulkan/context.h"
#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace gibake::test {

inline std::string cornell_sample_arg() {
  return shell_quote(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf");
}

// A path in the temporary directory, named by the test file's prefix, the process (test runs of
// two checkouts at once must not share files) and the case.
inline std::string vk_cli_tmp(const std::string& prefix, const std::string& name) {
  return (gibake::test::process_tmp() / (prefix + name)).string();
}

// Whether a listed device with compute satisfies `kind` (e.g. &vk::DeviceInfo::is_gpu).
inline bool have_vk_device(bool (vk::DeviceInfo::*kind)() const) {
  std::vector<vk::DeviceInfo> devices;
  if (!vk::list_devices(devices)) return false;
  for (const auto& d : devices)
    if ((d.*kind)() && d.compute) return true;
  return false;
}

}  // namespace gibake::test
