// The LPV bake's device contract: the propagation of one cascade, implemented on the CPU
// (lpv_propagate_volume, the reference) and on Vulkan (bake/vulkan/lpv.h); make_lpv_device
// (bake/pipeline/devices.h) picks one.
#pragma once
#include <memory>
#include <vector>

#include "io/context.h"
#include "io/status.h"
#include "kernels/lpv.h"

namespace gibake {

class LpvDevice {
 public:
  virtual ~LpvDevice() = default;
  // lpv_propagate_volume's inputs and result (bake/lpv/lpv.h): `cells` the injected light,
  // geometry null for no occlusion; `accumulated` the injected light plus every step.
  virtual Status propagate(const kernels::LpvGrid& grid, std::vector<kernels::LpvCell> cells, const float* geometry,
                           int iterations, const Context& ctx, std::vector<kernels::LpvCell>& accumulated) = 0;
};

std::unique_ptr<LpvDevice> make_cpu_lpv_device();

}  // namespace gibake
