// LPV propagation on a Vulkan device: the twin of lpv_propagate_volume (bake/lpv/lpv.h), the flux
// normalisation and the gather + accumulation of every step as compute kernels
// (kernels/shaders/lpv_scale.comp, lpv_propagate.comp), all steps in one submission.
#pragma once
#include <memory>
#include <vector>

#include "bake/lpv/lpv_device.h"
#include "io/status.h"
#include "kernels/lpv.h"
#include "kernels/vulkan/context.h"

namespace gibake {

// Same inputs and result as lpv_propagate_volume (geometry may be null: no occlusion).
Status lpv_propagate_volume_gpu(vk::Context& vk, const kernels::LpvGrid& grid,
                                const std::vector<kernels::LpvCell>& cells, const float* geometry, int iterations,
                                std::vector<kernels::LpvCell>& accumulated);

// The LPV device contract on `vk`; `own` (may be null) is a context the device keeps open for itself.
std::unique_ptr<LpvDevice> make_vulkan_lpv_device(vk::Context& vk, std::unique_ptr<vk::Context> own);

}  // namespace gibake
