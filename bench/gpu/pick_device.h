// The device a GPU benchmark runs on: an index, "lavapipe", or part of a name from
// `gibake info --devices`; empty: the first real GPU. -1 when none matches.
#pragma once
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

}  // namespace gibake::bench
