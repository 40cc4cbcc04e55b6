// Diffuse cone-traced irradiance of a voxel-GI volume at query points on a Vulkan device: the
// kernel kernels/shaders/vxgi_diffuse.comp over the GLSL include engines use
// (kernels/shaders/vxgi_cone.glsl), the twin of loader::cone_trace_diffuse with default options
// but ConeOptions::use_sdf = false (the include takes no empty-space steps).
#pragma once
#include <vector>

#include "gibake/loader.hpp"
#include "io/status.h"
#include "kernels/vulkan/context.h"

namespace gibake {

Status vxgi_diffuse_gpu(vk::Context& vk, const loader::VxgiVolume& volume, const std::vector<loader::Vec3>& points,
                        const std::vector<loader::Vec3>& normals, std::vector<loader::Rgb>& out);

}  // namespace gibake
