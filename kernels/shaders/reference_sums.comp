// The reconstruction check's reference paths summed per point on the device, in path order, as
// bake/preview/reconstruction_check.cpp sums them on the host: the radiance of the paths and their
// light samples, each half's luminance (float here, double there: only the noise estimate reads
// them) and path count, and the paths' rays; with a probe field, the same of the paths ended at their
// first hit in it. One point per invocation; path.comp mode 2 wrote the briefs. A
// dispatch sums one window of each point's paths (push.counts.zw, GPU_RAY_WINDOW at most) on top of
// the sums the window before stored, so no loop grows with the paths.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Briefs { GpuPathBrief briefs[]; };
layout(std430, set = 0, binding = 1) buffer Sums { GpuReferenceSums sums[]; };
// With push.flags.x: each path's radiance ended at its first hit in a probe field, the xyz of the
// first of its three vec4s (probe_field_ended.comp).
layout(std430, set = 0, binding = 2) readonly buffer Ended { vec4 ended_in[]; };
layout(push_constant) uniform Push { ReferenceSumsPush push; };

void main() {
  const uint p = GIBAKE_FLAT_INVOCATION;
  if (p >= push.counts.x) return;
  const uint rays = push.counts.y, w0 = push.counts.z, w1 = min(rays, w0 + push.counts.w);
  vec3 sum = vec3(0.0);
  float half_lum[2] = float[2](0.0, 0.0);
  uint half_count[2] = uint[2](0u, 0u);
  uint shadow_rays = 0u, bounce_rays = 0u, traced = 0u;
  const bool with_ended = push.flags.x != 0u;
  vec3 ended = vec3(0.0);
  float ended_half_lum[2] = float[2](0.0, 0.0);
  if (w0 > 0u) {  // the windows before
    const GpuReferenceSums s = sums[p];
    sum = s.sum.xyz;
    half_lum = float[2](s.sum.w, s.half_lum.x);
    ended = s.ended.xyz;
    ended_half_lum = float[2](s.ended.w, s.half_lum.y);
    half_count = uint[2](s.counts.x, s.counts.y);
    shadow_rays = s.counts.z;
    bounce_rays = s.counts.w;
    traced = s.traced.x;
  }
  for (uint r = w0; r < w1; ++r) {
    const GpuPathBrief b = briefs[p * rays + r];
    const uint h = b.counts.z;
    ++half_count[h];
    if (b.counts.w != 0u) ++traced;  // a path below its surface brings only its light sample
    shadow_rays += b.counts.x;
    bounce_rays += b.counts.y;
    const vec3 l = b.radiance_t.xyz;
    sum += l;
    half_lum[h] += 0.2126 * l.x + 0.7152 * l.y + 0.0722 * l.z;
    if (with_ended) {
      const vec3 e = ended_in[3u * (p * rays + r)].xyz;
      ended += e;
      ended_half_lum[h] += 0.2126 * e.x + 0.7152 * e.y + 0.0722 * e.z;
    }
  }
  sums[p] = GpuReferenceSums(vec4(sum, half_lum[0]), vec4(half_lum[1], ended_half_lum[1], 0.0, 0.0),
                             uvec4(half_count[0], half_count[1], shadow_rays, bounce_rays), uvec4(traced, 0u, 0u, 0u),
                             vec4(ended, ended_half_lum[0]));
}
