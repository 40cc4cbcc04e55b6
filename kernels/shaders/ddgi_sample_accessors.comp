// The GLSL sampler through accessors an engine defines (the include's first way), here over data
// the loader decoded on the CPU: float SH, states as uints, offsets, the depth atlas as vec2s with
// its width in GibakeDdgiVolume::engine.x, the irradiance atlas as vec4s (RGB, alpha) with its width
// in engine.y, the slot map of a sparse volume. tests/vulkan/ddgi_sample_glsl_test.cpp compares it with the CPU sampler and with
// ddgi_sample.comp (the section-buffer way).
#version 450
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Sh { float sh[]; };  // [probe][coefficient][rgb]
layout(std430, set = 0, binding = 1) readonly buffer States { uint states[]; };
layout(std430, set = 0, binding = 2) readonly buffer Offsets { vec4 offsets[]; };
layout(std430, set = 0, binding = 3) readonly buffer Depth { vec2 depth[]; };
layout(std430, set = 0, binding = 4) readonly buffer Irradiance { vec4 irradiance_atlas[]; };
layout(std430, set = 0, binding = 5) readonly buffer Slots { uint slots[]; };  // per probe of the grid

#define GIBAKE_DDGI_SH(v, probe, c) \
  vec3(sh[((probe) * uint((v).counts.w) + (c)) * 3u], sh[((probe) * uint((v).counts.w) + (c)) * 3u + 1u], \
       sh[((probe) * uint((v).counts.w) + (c)) * 3u + 2u])
#define GIBAKE_DDGI_STATE(v, probe) states[probe]
#define GIBAKE_DDGI_OFFSET(v, probe) offsets[probe].xyz
#define GIBAKE_DDGI_DEPTH(v, texel) depth[uint((texel).y) * (v).engine.x + uint((texel).x)]
#define GIBAKE_DDGI_IRRADIANCE(v, texel) irradiance_atlas[uint((texel).y) * (v).engine.y + uint((texel).x)].rgb
#define GIBAKE_DDGI_SLOT(v, probe) slots[probe]
#include "gibake/ddgi_sample.glsl"

layout(std430, set = 0, binding = 6) readonly buffer Params {
  GibakeDdgiVolume volume;
  GibakeSampleOptions options;
  uint query_count;
};
layout(std430, set = 0, binding = 7) readonly buffer Queries { vec4 queries[]; };  // P, N per query
layout(std430, set = 0, binding = 8) writeonly buffer Result { vec4 irradiance[]; };

void main() {
  const uint q = gl_GlobalInvocationID.x;
  if (q >= query_count) return;
  irradiance[q] = vec4(gibake_ddgi_irradiance(volume, queries[2u * q].xyz, queries[2u * q + 1u].xyz, options), 0.0);
}
