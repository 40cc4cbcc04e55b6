// The surface fit's paths ended at their first hit in a bake's probes (path_gather.cpp
// path_radiance's probe_lit): each path's first hit, as path_probe_field.comp recorded it, lit by
// the probes' irradiance through the GLSL sampler (probe_field.glsl), written over the record's
// first vec4 (xyz) for reference_sums.comp. One path per invocation; a kernel of its own, so that
// the sampler's registers do not weigh on the path tracing.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 64) in;
// Three vec4s a path: (radiance up to the hit + its light sample, p.x), (weight, p.y), (n, p.z).
layout(std430, set = 0, binding = 0) buffer FirstHits { vec4 first_hits[]; };
#define PROBE_FIELD_BINDING 1
#include "probe_field.glsl"
layout(push_constant) uniform Push { uvec4 counts; };  // x: paths

const float kPi = 3.14159265358979323846;

void main() {
  const uint i = GIBAKE_FLAT_INVOCATION;
  if (i >= counts.x) return;
  const vec4 a = first_hits[3u * i], b = first_hits[3u * i + 1u], c = first_hits[3u * i + 2u];
  if (b.x == 0.0 && b.y == 0.0 && b.z == 0.0) return;  // the probes add nothing: the radiance stands
  const vec3 ended = a.xyz + b.xyz * probe_field_irradiance(vec3(a.w, b.w, c.w), c.xyz) * (1.0 / kPi);
  first_hits[3u * i] = vec4(ended, a.w);
}
