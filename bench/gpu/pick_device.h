// The device a GPU benchmark runs on: an index, "lavapipe", or part of a name from
// `gibake info --devices`; empty: the first real GPU. -1 when none matches.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "kernels/vulkan/context.h"

namespace gibake::bench {

inline int pick_device(const std::vector<vk::DeviceInfo>& devices, const std::string& want) {
  for (const auto& d : devices) {
    if (!want.empty() && (want == std::to_string(d.index) || (want == "lavapipe" && d.is_lavapipe()) ||
                          d.name.find(want) != std::string::npos))
      return int(d.index);
    if (want.empty() && d.is_gpu()) return int(d.index);
  }
  return -1;
}

// Opens the device pick_device chooses; an error naming `want` when none matches.
inline Status open_device(const std::string& want, std::unique_ptr<vk::Context>& out) {
  std::vector<vk::DeviceInfo> devices;
  GIBAKE_TRY(vk::list_devices(devices));
  const int index = pick_device(devices, want);
  if (index < 0)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "no Vulkan device matching '" + want + "'");
  vk::ContextOptions options;
  options.device_index = uint32_t(index);
  return vk::Context::create(options, out);
}

}  // namespace gibake::bench
