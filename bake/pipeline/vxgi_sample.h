// `gibake sample --source vxgi --backend vulkan`: the diffuse cone trace of a file's voxel-GI
// clipmaps at points on a Vulkan device (bake/vulkan/vxgi.h), opened here, so that a caller holds
// no device of its own.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "bake/run/backend.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_sample.h"

namespace gibake {

// What ran on the device: the queries (the points inside a clipmap), the device's name, and the
// seconds of the trace with its uploads and readback (not the device's opening).
struct DeviceSampleReport {
  size_t queries = 0;
  std::string device;
  double seconds = 0.0;
};

// Irradiance (lux) at every point inside one of the file's clipmaps, on the Vulkan device that
// `settings` names (its backend is taken as Vulkan); the other points get none. A device that does
// not open fails as the bake's does (resolve_backend, open_vulkan); no clipmap: nothing opens.
Status sample_vxgi_vulkan(const BackendSettings& settings, const loader::BakeFile& file,
                          std::vector<SamplePoint>& points, DeviceSampleReport& report);

}  // namespace gibake
