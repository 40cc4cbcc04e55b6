// One probe-feedback bounce pass: the twin of the per-probe body of run_bounce_passes
// (bake/ddgi/bounce.cpp). Every bouncing hit is re-shaded with the irradiance of the previous pass's
// SH through its precomputed 8-probe weights (ddgi_irradiance_from_weights, shade_indirect), then
// integrated into SH (and, on the last pass, irradiance texels) as kernels::integrate_radiance
// does, scaled by hits/rays and added to pass 0. One workgroup per probe: each tile of hits is
// shaded one hit per invocation into shared memory, then every output value is summed by one
// invocation over the probe's hits in ray order -- the CPU's order -- so results are deterministic.
// `precise` keeps the compiler from fusing multiply-adds the CPU does not fuse. A dispatch sums one
// window of each probe's hits (push.window, GPU_RAY_WINDOW at most): a probe with more takes a
// dispatch per window, the sums carried between them in binding 8 (a vec4 per invocation of each
// workgroup of the dispatch), so no loop grows with the rays.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = GPU_BOUNCE_PASS_GROUP) in;
layout(std430, set = 0, binding = 0) readonly buffer Hits { GpuBounceHit hits[]; };
layout(std430, set = 0, binding = 1) readonly buffer Weights { GpuProbeWeights weights[]; };
layout(std430, set = 0, binding = 2) readonly buffer Probes { GpuBounceProbe probes[]; };
layout(std430, set = 0, binding = 3) readonly buffer IrrDirs { vec4 irr_dirs[]; };  // 8x8 texel directions
layout(std430, set = 0, binding = 4) readonly buffer Base { float sh_base[]; };     // pass 0
layout(std430, set = 0, binding = 5) readonly buffer Prev { float sh_prev[]; };     // pass k-1
layout(std430, set = 0, binding = 6) writeonly buffer Cur { float sh_cur[]; };      // pass k
layout(std430, set = 0, binding = 7) buffer Irr { float irr[]; };                   // pass-0 texels, += last pass
layout(std430, set = 0, binding = 8) buffer Carry { vec4 carry[]; };              // sums between windows
layout(push_constant) uniform Push { BouncePush push; };

shared vec4 s_dir[GPU_BOUNCE_PASS_GROUP];
shared vec4 s_rad[GPU_BOUNCE_PASS_GROUP];
shared float s_basis[GPU_BOUNCE_PASS_GROUP][9];  // sh_basis of each hit's direction

#define MAX_SH_VALUES 27

// kernels::sh_basis, coefficient c only.
float sh_basis(vec3 d, uint c) {
  precise float y;
  switch (c) {
    case 0: y = 0.282095; break;
    case 1: y = 0.488603 * d.y; break;
    case 2: y = 0.488603 * d.z; break;
    case 3: y = 0.488603 * d.x; break;
    case 4: y = 1.092548 * d.x * d.y; break;
    case 5: y = 1.092548 * d.y * d.z; break;
    case 6: y = 0.315392 * (3.0 * d.z * d.z - 1.0); break;
    case 7: y = 1.092548 * d.x * d.z; break;
    default: y = 0.546274 * (d.x * d.x - d.y * d.y); break;
  }
  return y;
}

float band_factor(uint c) { return c == 0u ? push.params.y : (c < 4u ? push.params.z : push.params.w); }

// ddgi_irradiance_from_weights then shade_indirect: the outgoing bounce radiance of one hit.
vec3 bounce_radiance(GpuBounceHit hit, GpuProbeWeights pw) {
  // Loops over the largest count with a uniform guard: constant trip counts let the compiler
  // unroll them and keep avg[] in registers instead of indexed local memory.
  const uint values = push.range.z * 3u;
  precise float avg[MAX_SH_VALUES];
  for (uint k = 0u; k < MAX_SH_VALUES; ++k) avg[k] = 0.0;
  for (uint i = 0u; i < 8u; ++i) {
    const uint probe = i < 4u ? pw.probe_lo[i] : pw.probe_hi[i - 4u];
    if (probe == GPU_BOUNCE_NO_PROBE) break;
    const float w = i < 4u ? pw.weight_lo[i] : pw.weight_hi[i - 4u];
    for (uint k = 0u; k < MAX_SH_VALUES; ++k)
      if (k < values) avg[k] += w * sh_prev[probe * values + k];
  }
  const vec3 n = hit.normal_probe.xyz;
  precise vec3 e = vec3(0.0);
  for (uint c = 0u; c < MAX_SH_VALUES / 3u; ++c) {  // sh_irradiance
    if (c >= push.range.z) break;
    precise float w = band_factor(c) * sh_basis(n, c);
    e += vec3(avg[c * 3u], avg[c * 3u + 1u], avg[c * 3u + 2u]) * w;
  }
  e = vec3(e.x < 0.0 ? 0.0 : e.x, e.y < 0.0 ? 0.0 : e.y, e.z < 0.0 ? 0.0 : e.z);  // std::max(e, 0)
  precise vec3 l = hit.albedo.xyz * e * push.params.x;
  return l;
}

void main() {
  const uint t = gl_LocalInvocationID.x;
  if (gl_WorkGroupID.x >= push.range.y) return;  // uniform per workgroup: no barrier is skipped by part of a group
  const uint p = push.range.x + gl_WorkGroupID.x;
  const uint values = push.range.z * 3u;
  const bool last = push.range.w != 0u;
  const GpuBounceProbe probe = probes[p];
  const uint n = probe.range.y, w0 = push.window.x, w1 = min(n, w0 + push.window.y);
  if (w0 > 0u && w0 >= n) return;  // uniform too: the probe ended in an earlier window
  if (probe.position.w != 0.0) {  // inactive: zero SH, pass-0 texels kept
    if (t < values) sh_cur[p * values + t] = 0.0;
    return;
  }
  const uint first_hit = probe.range.x;
  const float norm = uintBitsToFloat(probe.range.z), scale = uintBitsToFloat(probe.range.w);
  const vec3 it = irr_dirs[min(t, GPU_IRRADIANCE_TEXELS - 1u)].xyz;
  const bool irr_lane = last && t < GPU_IRRADIANCE_TEXELS;
  const uint sh_i = t - GPU_IRRADIANCE_TEXELS;  // SH value (coefficient x 3 + channel) of this lane
  const bool sh_lane = t >= GPU_IRRADIANCE_TEXELS && sh_i < values;
  const uint carry_at = gl_WorkGroupID.x * GPU_BOUNCE_PASS_GROUP + t;
  precise vec3 irr_sum = vec3(0.0);
  precise float sh = 0.0;
  if (w0 > 0u) {  // the windows before
    irr_sum = carry[carry_at].xyz;
    sh = carry[carry_at].w;
  }
  for (uint first = w0; first < w1; first += GPU_BOUNCE_PASS_GROUP) {
    barrier();  // the previous tile is read by everyone
    if (first + t < w1) {
      const uint h = first_hit + first + t;
      s_dir[t] = hits[h].dir_t;
      s_rad[t] = vec4(bounce_radiance(hits[h], weights[h]), 0.0);
      // The basis once per hit, not per SH lane (no 9-way switch inside the summing loop).
      for (uint c = 0u; c < 9u; ++c) s_basis[t][c] = sh_basis(hits[h].dir_t.xyz, c);
    }
    barrier();
    const uint count = min(GPU_BOUNCE_PASS_GROUP, w1 - first);
    for (uint r = 0u; r < count; ++r) {
      const vec3 l = s_rad[r].xyz;
      if (l == vec3(0.0)) continue;  // the CPU skips dark rays
      if (irr_lane) {
        const vec3 d = s_dir[r].xyz;
        precise float c = it.x * d.x + it.y * d.y + it.z * d.z;
        precise float w = c > 0.0 ? c : 0.0;  // std::max(0.f, c)
        irr_sum += l * w;
      } else if (sh_lane) {
        sh += l[sh_i % 3u] * s_basis[r][sh_i / 3u];
      }
    }
  }
  if (w1 < n) {  // more windows follow
    carry[carry_at] = vec4(irr_sum, sh);
    return;
  }
  if (sh_lane) {
    precise float add = sh * norm;
    precise float v = sh_base[p * values + sh_i] + add * scale;
    sh_cur[p * values + sh_i] = v;
  }
  if (irr_lane) {
    const uint ibase = p * GPU_IRRADIANCE_TEXELS * 3u + t * 3u;
    precise vec3 add = irr_sum * norm;
    precise vec3 v = vec3(irr[ibase], irr[ibase + 1u], irr[ibase + 2u]) + add * scale;
    irr[ibase] = v.x;
    irr[ibase + 1u] = v.y;
    irr[ibase + 2u] = v.z;
  }
}
