// Diffuse cone-traced irradiance at query points (vxgi_cone.glsl over the bake file's layout in
// storage buffers): the Vulkan kernel CI checks against the loader's CPU tracer.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Params { GpuVxgiParams params; };
layout(std430, set = 0, binding = 1) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 2) readonly buffer Points { vec4 points[]; };  // p, n pairs
layout(std430, set = 0, binding = 3) writeonly buffer Out { vec4 irradiance[]; };
layout(push_constant) uniform Push { uvec4 count; };  // x: points

#include "vxgi_cone.glsl"

GibakeVxgiVolume volume() {
  return GibakeVxgiVolume(params.grid_min_size.xyz, params.grid_min_size.w, ivec3(params.dims_levels.xyz),
                          params.dims_levels.w, params.sky_scale.xyz, params.sky_scale.w);
}

vec4 gibake_vxgi_fetch(uint level, uint face, ivec3 c) { return radiance[gibake_vxgi_index(volume(), level, face, c)]; }

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count.x) return;
  vec3 e = gibake_vxgi_cone_trace_diffuse(volume(), points[2 * i].xyz, points[2 * i + 1].xyz,
                                          gibake_default_cone_options());
  irradiance[i] = vec4(e, 0.0);
}
