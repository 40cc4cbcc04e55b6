// Diffuse cone-traced irradiance (and the specular cone) of a file's voxel-GI clipmaps at query points on a Vulkan
// device: the kernel kernels/shaders/vxgi_diffuse.comp over the GLSL include engines use
// (kernels/shaders/vxgi_cone.glsl), the twin of loader::cone_trace_diffuse with default options
// (use_sdf: SDF steps where a clipmap has an SDF, as ConeOptions::use_sdf; precomputed_cones: the 16
// precomputed cone directions, reading the slices a volume has, as ConeOptions::precomputed_cones).
#pragma once
#include <vector>

#include "gibake/loader.hpp"
#include "io/status.h"
#include "kernels/vulkan/context.h"

namespace gibake {

Status vxgi_diffuse_gpu(vk::Context& vk, const loader::VxgiClipmaps& clipmaps, const std::vector<loader::Vec3>& points,
                        const std::vector<loader::Vec3>& normals, std::vector<loader::Rgb>& out, bool use_sdf = true,
                        bool precomputed_cones = false);

// The specular cone at query points (loader::cone_trace_specular with default options and
// use_sdf): premultiplied radiance and alpha of a cone about to_eye's mirror direction in the normal.
struct SpecularQuery {
  loader::Vec3 point, normal, to_eye;
  float roughness = 0.f;
};
Status vxgi_specular_gpu(vk::Context& vk, const loader::VxgiClipmaps& clipmaps,
                         const std::vector<SpecularQuery>& queries, std::vector<loader::Rgba>& out,
                         bool use_sdf = true);

}  // namespace gibake
