// The GLSL sampler (io/loader/include/gibake/ddgi_sample.glsl, shipped to engines) at a list of
// query points, reading a bake file's section payloads as the file stores them
// (GIBAKE_DDGI_SECTION_BUFFERS). tests/vulkan/ddgi_sample_glsl_test.cpp compares every query with
// the loader's CPU sampler, so what an engine runs is what gibake measures.
#version 450
#extension GL_GOOGLE_include_directive : require
#define GIBAKE_DDGI_SECTION_BUFFERS
#define GIBAKE_DDGI_BINDING 0
#include "gibake/ddgi_sample.glsl"

layout(local_size_x = 64) in;
// Bindings 0..5: the ddgi_sh, ddgi_states, ddgi_offsets, ddgi_depth, ddgi_irradiance and
// ddgi_probe_slots payloads (the include's).
layout(std430, set = 0, binding = 6) readonly buffer Params {
  GibakeDdgiVolume volume;
  GibakeSampleOptions options;
  uint query_count;
};
layout(std430, set = 0, binding = 7) readonly buffer Queries { vec4 queries[]; };  // P, N per query
layout(std430, set = 0, binding = 8) writeonly buffer Irradiance { vec4 irradiance[]; };

void main() {
  const uint q = gl_GlobalInvocationID.x;
  if (q >= query_count) return;
  irradiance[q] = vec4(gibake_ddgi_irradiance(volume, queries[2u * q].xyz, queries[2u * q + 1u].xyz, options), 0.0);
}
