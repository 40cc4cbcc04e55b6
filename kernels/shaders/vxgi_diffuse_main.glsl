// The body of vxgi_diffuse.comp (64 invocations a group) and vxgi_diffuse_serial.comp (1, for
// lavapipe): diffuse cone-traced irradiance at query points, vxgi_cone.glsl over the bake file's
// layout in storage buffers, every clipmap. The includer defines GIBAKE_VXGI_GROUP.
#include "gpu_types.h"

layout(local_size_x = GIBAKE_VXGI_GROUP) in;
layout(std430, set = 0, binding = 0) readonly buffer Params { GpuVxgiParams params[]; };  // per clipmap
layout(std430, set = 0, binding = 1) readonly buffer Radiance { vec4 radiance[]; };  // clipmaps one after the other
// p, n pairs; with the specular cone (count.w 2) p (w: roughness), n, to_eye triples.
layout(std430, set = 0, binding = 2) readonly buffer Points { vec4 points[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Out { vec4 irradiance[]; };
layout(std430, set = 0, binding = 4) readonly buffer Sdf { float sdf[]; };  // level-0 voxels per clipmap (one 0 when none)
// x: points, y: 1 = SDF steps, z: clipmaps, w: 0 = the 6 diffuse cones, 1 = the 16 precomputed
// cone directions, 2 = the specular cone
layout(push_constant) uniform Push { uvec4 count; };

#define GIBAKE_VXGI_SDF
#include "vxgi_cone.glsl"

uint gibake_vxgi_clipmap_count() { return count.z; }

GibakeVxgiVolume gibake_vxgi_clipmap(uint k) {
  GpuVxgiParams p = params[k];
  return GibakeVxgiVolume(p.grid_min_size.xyz, p.grid_min_size.w, ivec3(p.dims_levels.xyz), p.dims_levels.w,
                          p.sky_scale.xyz, p.sky_scale.w, k, p.flags.x != 0u, p.flags.w);  // faces stored
}

vec4 gibake_vxgi_fetch(uint clipmap, uint level, uint face, ivec3 c) {
  return radiance[params[clipmap].flags.y + gibake_vxgi_index(gibake_vxgi_clipmap(clipmap), level, face, c)];
}

float gibake_vxgi_fetch_sdf(uint clipmap, ivec3 c) {
  ivec3 d = ivec3(params[clipmap].dims_levels.xyz);
  return sdf[params[clipmap].flags.z + uint(c.x + d.x * (c.y + d.y * c.z))];
}

void main() {
  // A flat grid folded into rows (vk::Dispatch::flat_groups): groups past a row continue in y.
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  if (i >= count.x) return;
  GibakeConeOptions o = gibake_default_cone_options();
  o.use_sdf = count.y != 0u;
  if (count.w == 2u) {
    irradiance[i] = gibake_vxgi_cone_trace_specular(points[3 * i].xyz, points[3 * i + 1].xyz, points[3 * i + 2].xyz,
                                                    points[3 * i].w, o);
    return;
  }
  vec3 p = points[2 * i].xyz, n = points[2 * i + 1].xyz;
  irradiance[i] = vec4(count.w != 0u ? gibake_vxgi_cone_trace_diffuse_precomputed(p, n, o)
                                     : gibake_vxgi_cone_trace_diffuse(p, n, o), 0.0);
}
