// Per-probe statistics of the path gather from its GpuPathBriefs, so that only one GpuProbeStats per
// probe crosses the bus instead of 32 bytes a ray: the twins of count_path (bake/vulkan/path.cpp), the
// ray test's misses and saw-light flag (ProbeIntegrator::ray_test) and RunningStats::add
// (bake/ddgi/trace_stage.cpp). One invocation per probe walks its rays in ray order, so the sums, the
// minimum and the Welford recurrence take the CPU's operations in the CPU's order (`precise`: no
// fused multiply-adds) and give its bits wherever the device rounds doubles correctly. Dispatched
// after every path batch; a probe whose rays straddle batches continues from its stored state.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = GPU_PROBE_STATS_GROUP) in;
layout(std430, set = 0, binding = 0) readonly buffer Briefs { GpuPathBrief briefs[]; };
layout(std430, set = 0, binding = 1) buffer Stats { GpuProbeStats stats[]; };
// With push.range.w: each ray's paired emitter sample (path.comp light_out), batch-indexed as the briefs.
layout(std430, set = 0, binding = 2) readonly buffer Lights { GpuRaySample lights[]; };
layout(push_constant) uniform Push { ProbeStatsPush push; };

void main() {
  const uint first = push.range.x, count = push.range.y, per_probe = push.range.z;
  const uint slot = first / per_probe + gl_GlobalInvocationID.x;
  const uint lo = max(first, slot * per_probe), hi = min(first + count, (slot + 1u) * per_probe);
  if (lo >= hi) return;
  GpuProbeStats s;
  if (lo == slot * per_probe)  // the probe's first ray: a fresh state
    s = GpuProbeStats(uvec4(0u), uvec4(0u, 0u, floatBitsToUint(-1.0), 0u), uvec4(0u));
  else
    s = stats[slot];
  precise double mean = packDouble2x32(s.welford.xy), m2 = packDouble2x32(s.welford.zw);
  float nearest = uintBitsToFloat(s.test.z);
  for (uint r = lo; r < hi; ++r) {
    const GpuPathBrief b = briefs[r - first];
    const vec3 c = b.radiance_t.xyz;
    s.counts += uvec4(1u, b.counts.xyz);
    s.test.x += b.counts.w == 0u ? 1u : 0u;  // HitKind miss
    if (c.r > 0.0 || c.g > 0.0 || c.b > 0.0) s.test.y = 1u;
    if (b.counts.w == 1u && (nearest < 0.0 || b.radiance_t.w < nearest)) nearest = b.radiance_t.w;
    precise float lum = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    precise double x = double(lum);
    if (push.range.w != 0u) {  // the combined estimator's term: the ray's plus its emitter sample's
      const vec3 e = lights[r - first].radiance.xyz;
      precise float lum_e = 0.2126 * e.r + 0.7152 * e.g + 0.0722 * e.b;
      x = x + double(lum_e);
    }
    precise double d = x - mean;
    mean += d / double(s.counts.x);
    m2 += d * (x - mean);
  }
  s.test.z = floatBitsToUint(nearest);
  s.welford = uvec4(unpackDouble2x32(mean), unpackDouble2x32(m2));
  stats[slot] = s;
}
