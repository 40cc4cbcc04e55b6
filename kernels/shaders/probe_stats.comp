// Per-probe statistics of the path gather from its GpuPathBriefs, so that only one GpuProbeStats per
// probe crosses the bus instead of 32 bytes a ray: the twins of count_path (bake/vulkan/path.cpp), the
// ray test's misses and saw-light flag (ProbeIntegrator::ray_test) and RunningStats::add
// (bake/ddgi/trace_batches.cpp). One invocation per probe walks its rays in ray order, so the sums, the
// minimum and the Welford recurrence take the CPU's operations in the CPU's order (`precise`: no
// fused multiply-adds) and give its bits wherever the device rounds doubles correctly. Dispatched
// after every path batch, once per window of GPU_RAY_WINDOW rays of each probe (window after window,
// in ray order); a probe whose rays straddle batches or windows continues from its stored state, and
// with --target-error (push.range.w bit 1) every probe continues from the state the host uploaded,
// its statistics over the passes before (a fresh state for the first), as RunningStats continues.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"
#include "stop_value.glsl"

layout(local_size_x = GPU_PROBE_STATS_GROUP) in;
layout(std430, set = 0, binding = 0) readonly buffer Briefs { GpuPathBrief briefs[]; };
layout(std430, set = 0, binding = 1) buffer Stats { GpuProbeStats stats[]; };
// With push.range.w bit 0: each ray's paired emitter sample (path.comp light_out), batch-indexed as the briefs.
layout(std430, set = 0, binding = 2) readonly buffer Lights { GpuRaySample lights[]; };
layout(push_constant) uniform Push { ProbeStatsPush push; };

void main() {
  const uint first = push.range.x, count = push.range.y, per_probe = push.range.z;
  const uint slot = first / per_probe + GIBAKE_FLAT_INVOCATION;
  // This window of the probe's rays, within the batch.
  const uint w0 = slot * per_probe + push.window.x, w1 = w0 + min(push.window.y, per_probe - push.window.x);
  const uint lo = max(max(first, slot * per_probe), w0), hi = min(min(first + count, (slot + 1u) * per_probe), w1);
  if (push.window.x >= per_probe || lo >= hi) return;
  GpuProbeStats s;
  const bool paired = (push.range.w & 1u) != 0u, resume = (push.range.w & 2u) != 0u;
  if (lo == slot * per_probe && !resume)  // the probe's first ray: a fresh state
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
    const double x = ray_stop_value(c, paired, paired ? lights[r - first].radiance.xyz : vec3(0.0));
    precise double d = x - mean;
    mean += d / double(s.counts.x);
    m2 += d * (x - mean);
  }
  s.test.z = floatBitsToUint(nearest);
  s.welford = uvec4(unpackDouble2x32(mean), unpackDouble2x32(m2));
  stats[slot] = s;
}
