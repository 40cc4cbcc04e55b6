// An engine's fragment shader lighting a diffuse surface with gibake's GLSL sampler: the probe data
// in the engine's own resources (SH and offsets as decoded by gibake::loader, the depth atlas as an
// RG32F texture), read through the four accessors the include asks for. Built against the installed
// package (CMakeLists.txt) when glslc is found, so the shipped include is known to compile.
#version 450
#extension GL_GOOGLE_include_directive : require

layout(set = 1, binding = 0) readonly buffer ProbeSh { float probe_sh[]; };  // [probe][coefficient][rgb]
layout(set = 1, binding = 1) readonly buffer ProbeStates { uint probe_states[]; };
layout(set = 1, binding = 2) readonly buffer ProbeOffsets { vec4 probe_offsets[]; };
layout(set = 1, binding = 3) uniform sampler2D depth_atlas;  // RG32F, nearest; texelFetch only

#define GIBAKE_DDGI_SH(v, probe, c)                                                  \
  vec3(probe_sh[((probe) * uint((v).counts.w) + (c)) * 3u],                         \
       probe_sh[((probe) * uint((v).counts.w) + (c)) * 3u + 1u],                    \
       probe_sh[((probe) * uint((v).counts.w) + (c)) * 3u + 2u])
#define GIBAKE_DDGI_STATE(v, probe) probe_states[probe]
#define GIBAKE_DDGI_OFFSET(v, probe) probe_offsets[probe].xyz
#define GIBAKE_DDGI_DEPTH(v, texel) texelFetch(depth_atlas, texel, 0).xy
#include "gibake/ddgi_sample.glsl"

// gibake::loader::DdgiVolume::glsl_volume(), uploaded as it is.
layout(set = 1, binding = 4) uniform Volume { GibakeDdgiVolume volume; };

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec3 albedo;
layout(location = 0) out vec4 colour;

void main() {
  const vec3 irradiance = gibake_ddgi_irradiance(volume, world_position, normalize(world_normal));  // lux
  colour = vec4(albedo / 3.14159265 * irradiance, 1.0);  // diffuse radiance, cd/m^2
}
