// Probe rays -> SH, irradiance texels and depth moments: the twin of kernels::integrate_radiance
// and kernels::integrate_depth (kernels/integrate.cpp). One workgroup per probe; its rays pass
// through shared memory in tiles of 256, and every output value is summed by one invocation over
// the probe's rays in ray order, as the CPU sums it, so results are deterministic and differ from
// the CPU only by rounding. `precise` keeps the compiler from fusing multiply-adds the CPU does
// not fuse. With --target-error (bake/vulkan/integrate.h, accumulate) a probe's passes arrive one
// after another: each invocation then resumes its sums from the probe's accumulators and stores them
// back, so the sums over every pass are those over all the probe's rays in ray order (with emitter
// samples, each pass's rays then its samples), and the outputs are written normalized by the rays so
// far at every pass, final after the last. Outputs go to the probe's slot (range: acc.x).
// A dispatch walks one window of each probe's samples (push.counts.zw, GPU_RAY_WINDOW at most), so
// no invocation's loops grow with the rays: a probe with more samples takes a dispatch per window,
// each resuming the sums the window before stored in the slot's accumulators, in the same order.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 256) in;
layout(std430, set = 0, binding = 0) readonly buffer Samples { GpuRaySample samples[]; };
layout(std430, set = 0, binding = 1) readonly buffer Probes { GpuIntegrateProbe probes[]; };
layout(std430, set = 0, binding = 2) readonly buffer IrrDirs { vec4 irr_dirs[]; };    // 8x8 texel directions
layout(std430, set = 0, binding = 3) readonly buffer DepthDirs { vec4 depth_dirs[]; };  // 16x16
layout(std430, set = 0, binding = 4) writeonly buffer Sh { float sh_out[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Irr { float irr_out[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Depth { float depth_out[]; };
// Per slot and invocation two vec4s: (wd, wdd, wsum, best), (best_depth, irradiance rgb | SH value).
layout(std430, set = 0, binding = 7) buffer Accumulators { vec4 acc[]; };
layout(push_constant) uniform Push { IntegratePush push; };

shared vec4 s_dir[GPU_INTEGRATE_GROUP];
shared vec4 s_rad[GPU_INTEGRATE_GROUP];

// kernels::sh_basis, coefficient c only.
float sh_basis(vec3 d, uint c) {
  switch (c) {
    case 0: return 0.282095;
    case 1: return 0.488603 * d.y;
    case 2: return 0.488603 * d.z;
    case 3: return 0.488603 * d.x;
    case 4: return 1.092548 * d.x * d.y;
    case 5: return 1.092548 * d.y * d.z;
    case 6: return 0.315392 * (3.0 * d.z * d.z - 1.0);
    case 7: return 1.092548 * d.x * d.z;
    default: return 0.546274 * (d.x * d.x - d.y * d.y);
  }
}

void main() {
  const uint p = gl_WorkGroupID.x, t = gl_LocalInvocationID.x;
  if (p >= push.counts.x) return;  // uniform per workgroup: no barrier is skipped by part of a group
  const uvec4 range = probes[p].range;
  const uint w0 = push.counts.z, w1 = min(range.y, w0 + push.counts.w);
  if (w0 > 0u && w0 >= range.y) return;  // uniform too: the probe ended in an earlier window
  const uint out_slot = probes[p].acc.x, acc_flags = probes[p].acc.y;
  const bool load = (acc_flags & GPU_ACC_LOAD) != 0u || w0 > 0u;
  const bool store = (acc_flags & GPU_ACC_STORE) != 0u || w1 < range.y;
  const uint acc_at = (out_slot * GPU_INTEGRATE_GROUP + t) * 2u;
  const float norm = uintBitsToFloat(range.z);
  const uint depth_n = range.w;  // the rays; paired emitter samples after them take no part in the depth
  const uint coefs = push.counts.y;
  const float cos_cutoff = push.params.x;
  const vec3 dt = depth_dirs[t].xyz;
  const vec3 it = irr_dirs[min(t, GPU_IRRADIANCE_TEXELS - 1u)].xyz;
  const bool irr_lane = t < GPU_IRRADIANCE_TEXELS;
  const uint sh_i = t - GPU_IRRADIANCE_TEXELS;  // SH value (coefficient x 3 + channel) of this lane
  const bool sh_lane = t >= GPU_IRRADIANCE_TEXELS && sh_i < coefs * 3u;
  precise float wd = 0.0, wdd = 0.0, wsum = 0.0;  // depth texel t
  float best = -2.0, best_depth = 0.0;           // closest ray, for a texel no cone reached
  precise vec3 irr = vec3(0.0);
  precise float sh = 0.0;
  if (load) {  // the probe's sums over its passes (or windows) before
    const vec4 a = acc[acc_at], b = acc[acc_at + 1u];
    wd = a.x;
    wdd = a.y;
    wsum = a.z;
    best = a.w;
    best_depth = b.x;
    irr = b.yzw;
    sh = b.y;
  }
  for (uint first = w0; first < w1; first += GPU_INTEGRATE_GROUP) {
    barrier();  // the previous tile is read by everyone
    if (first + t < w1) {
      s_dir[t] = samples[range.x + first + t].dir_depth;
      s_rad[t] = samples[range.x + first + t].radiance;
    }
    barrier();
    const uint n = min(GPU_INTEGRATE_GROUP, w1 - first);
    for (uint r = 0u; r < n; ++r) {
      const vec3 d = s_dir[r].xyz;
      const float depth = s_dir[r].w;
      precise float c = dt.x * d.x + dt.y * d.y + dt.z * d.z;
      if (first + r < depth_n) {
        if (c > best) {
          best = c;
          best_depth = depth;
        }
        if (c >= cos_cutoff) {  // pow(c, 64) by repeated squaring, as the CPU
          precise float w = c * c;
          w *= w; w *= w; w *= w; w *= w; w *= w;
          precise float a = w * depth;
          precise float b = a * depth;
          wd += a;
          wdd += b;
          wsum += w;
        }
      }
      const vec3 l = s_rad[r].xyz;
      if (l == vec3(0.0)) continue;  // the CPU skips dark rays
      if (irr_lane) {
        precise float w = max(0.0, it.x * d.x + it.y * d.y + it.z * d.z);
        irr += l * w;
      } else if (sh_lane) {
        precise float y = sh_basis(d, sh_i / 3u);
        sh += l[sh_i % 3u] * y;
      }
    }
  }
  if (store) {
    acc[acc_at] = vec4(wd, wdd, wsum, best);
    acc[acc_at + 1u] = sh_lane ? vec4(best_depth, sh, 0.0, 0.0) : vec4(best_depth, irr);
  }
  if (w1 < range.y) return;  // the outputs once the probe's last window is summed
  const uint dbase = out_slot * GPU_DEPTH_TEXELS * 2u + t * 2u;
  if (wsum > 0.0) {
    depth_out[dbase] = wd / wsum;
    depth_out[dbase + 1u] = wdd / wsum;
  } else {
    depth_out[dbase] = best_depth;
    depth_out[dbase + 1u] = best_depth * best_depth;
  }
  if (irr_lane) {
    const uint ibase = out_slot * GPU_IRRADIANCE_TEXELS * 3u + t * 3u;
    irr_out[ibase] = irr.x * norm;
    irr_out[ibase + 1u] = irr.y * norm;
    irr_out[ibase + 2u] = irr.z * norm;
  }
  if (sh_lane) sh_out[out_slot * coefs * 3u + sh_i] = sh * norm;
}
