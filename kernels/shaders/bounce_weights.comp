// The 8-probe weights of every bouncing hit: the twin of kernels::ddgi_probe_weights with depth
// tiles (kernels/ddgi_sample.cpp): trilinear over the cell holding the hit, inactive probes
// skipped, smooth back-face weight, Chebyshev visibility from the bilinear depth moments, then
// normalised. One invocation per hit; the operations follow the CPU's in order and operands, and
// `precise` keeps the compiler from fusing multiply-adds the CPU does not fuse. The CPU sums the
// weights in double; this sums them in float (a few ulp apart, see tests/vulkan/gpu_bounce_test.cpp).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = GPU_BOUNCE_WEIGHTS_GROUP) in;
layout(std430, set = 0, binding = 0) readonly buffer Hits { GpuBounceHit hits[]; };
layout(std430, set = 0, binding = 1) readonly buffer Probes { GpuBounceProbe probes[]; };
layout(std430, set = 0, binding = 2) readonly buffer Depth { vec2 depth[]; };  // bordered tiles, probe after probe
layout(std430, set = 0, binding = 3) writeonly buffer Weights { GpuProbeWeights weights[]; };
layout(push_constant) uniform Push { BouncePush push; };

// kernels::saturate and std::max(x, c) with the CPU's NaN behaviour.
float saturate_cpu(float v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); }
float max_c_x(float c, float x) { return c < x ? x : c; }  // std::max(c, x)

float dot3(vec3 a, vec3 b) {
  precise float d = a.x * b.x + a.y * b.y + a.z * b.z;
  return d;
}

// encode_oct (kernels/octahedral.h).
vec2 encode_oct(vec3 d) {
  precise float inv = 1.0 / (abs(d.x) + abs(d.y) + abs(d.z));
  precise float px = d.x * inv, py = d.y * inv;
  if (d.z < 0.0) {
    precise float nx = (1.0 - abs(py)) * (px >= 0.0 ? 1.0 : -1.0);
    precise float ny = (1.0 - abs(px)) * (py >= 0.0 ? 1.0 : -1.0);
    px = nx;
    py = ny;
  }
  return vec2(px, py);
}

// oct_sample_bilinear_uv on probe `probe`'s bordered RG tile.
vec2 sample_depth(uint probe, vec2 uv) {
  const int res = int(push.counts.w), tile = res + 2;
  precise float fx = 1.0 + (uv.x * 0.5 + 0.5) * float(res) - 0.5;
  precise float fy = 1.0 + (uv.y * 0.5 + 0.5) * float(res) - 0.5;
  const int x0 = clamp(int(floor(fx)), 0, res), y0 = clamp(int(floor(fy)), 0, res);
  precise float ax = saturate_cpu(fx - float(x0));
  precise float ay = saturate_cpu(fy - float(y0));
  const uint base = probe * uint(tile * tile) + uint(y0 * tile + x0);
  const vec2 t00 = depth[base], t10 = depth[base + 1u];
  const vec2 t01 = depth[base + uint(tile)], t11 = depth[base + uint(tile) + 1u];
  precise vec2 a = t00 + (t10 - t00) * ax;
  precise vec2 b = t01 + (t11 - t01) * ax;
  precise vec2 m = a + (b - a) * ay;
  return m;
}

// The weight of one corner probe at `pos` before normalisation (probe_weights_scalar's loop body).
float corner_weight(uint probe, vec3 pos, vec3 p, vec3 n, float tri) {
  const float normal_bias = push.grid_min.w, smooth_bf = push.spacing.w;
  precise vec3 probe_to_point = (p - pos) + n * normal_bias;
  precise float dist = sqrt(dot3(probe_to_point, probe_to_point));
  precise float inv_dist = -1.0 / dist;
  const vec3 dir_to_probe = dist > 0.0 ? probe_to_point * inv_dist : n;
  precise vec3 to_probe = pos - p;
  precise float tl = sqrt(dot3(to_probe, to_probe));
  precise float inv_tl = 1.0 / tl;
  const vec3 true_dir = tl > 0.0 ? to_probe * inv_tl : vec3(0.0);
  precise float wrap = max_c_x(0.0001, (dot3(true_dir, n) + 1.0) * 0.5);
  precise float w = saturate_cpu(dot3(dir_to_probe, n)) * (1.0 - smooth_bf) + (wrap * wrap + 0.2) * smooth_bf;
  if (dist > 0.0) {
    const vec2 m = sample_depth(probe, encode_oct(-dir_to_probe));
    if (dist > m.x) {
      precise float sq = abs(m.x * m.x - m.y);
      precise float variance = sq < 1e-4 ? 1e-4 : sq;
      precise float diff = dist - m.x;
      precise float cheb = variance / (variance + diff * diff);
      w *= cheb * cheb * cheb;
    }
  }
  precise float wt = (w < 1e-6 ? 1e-6 : w) * tri;
  return wt;
}

void main() {
  const uint i = GIBAKE_FLAT_INVOCATION;
  if (i >= push.range.y) return;
  const uint h = push.range.x + i;
  const GpuBounceHit hit = hits[h];
  const vec3 origin = probes[uint(hit.normal_probe.w)].position.xyz;
  precise vec3 p = origin + hit.dir_t.xyz * hit.dir_t.w;
  const vec3 n = hit.normal_probe.xyz;
  // base_cell: the cell holding p and p's trilinear position inside it.
  ivec3 base = ivec3(0);
  vec3 alpha = vec3(0.0);
  for (int a = 0; a < 3; ++a) {
    const int count = int(push.counts[a]);
    if (count <= 1 || push.spacing[a] <= 0.0) continue;
    precise float g = (p[a] - push.grid_min[a]) / push.spacing[a];
    base[a] = clamp(int(floor(g)), 0, count - 2);
    precise float f = g - float(base[a]);
    alpha[a] = saturate_cpu(f);
  }
  uint probe_out[8] = uint[8](GPU_BOUNCE_NO_PROBE, GPU_BOUNCE_NO_PROBE, GPU_BOUNCE_NO_PROBE, GPU_BOUNCE_NO_PROBE,
                              GPU_BOUNCE_NO_PROBE, GPU_BOUNCE_NO_PROBE, GPU_BOUNCE_NO_PROBE, GPU_BOUNCE_NO_PROBE);
  float w_out[8] = float[8](0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
  uint count = 0u;
  precise float sum_w = 0.0;
  for (int k = 0; k < 8; ++k) {  // cell_corner: bit 0 +x, bit 1 +y, bit 2 +z
    const ivec3 off = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    const ivec3 c = min(base + off, ivec3(push.counts.xyz) - 1);
    const uint probe = uint(c.x) + push.counts.x * (uint(c.y) + push.counts.y * uint(c.z));
    if (probes[probe].position.w != 0.0) continue;
    precise float tri = (off.x != 0 ? alpha.x : 1.0 - alpha.x) * (off.y != 0 ? alpha.y : 1.0 - alpha.y) *
                        (off.z != 0 ? alpha.z : 1.0 - alpha.z);
    if (!(tri > 0.0)) continue;
    precise vec3 pos = push.grid_min.xyz + push.spacing.xyz * vec3(c);
    pos += probes[probe].offset.xyz;
    probe_out[count] = probe;
    w_out[count] = corner_weight(probe, pos, p, n, tri);
    sum_w += w_out[count];
    ++count;
  }
  if (!(sum_w > 0.0)) count = 0u;
  GpuProbeWeights out_w;
  for (uint k = 0u; k < 8u; ++k) {
    precise float wn = k < count ? w_out[k] / sum_w : 0.0;
    const uint pr = k < count ? probe_out[k] : GPU_BOUNCE_NO_PROBE;
    if (k < 4u) {
      out_w.probe_lo[k] = pr;
      out_w.weight_lo[k] = wn;
    } else {
      out_w.probe_hi[k - 4u] = pr;
      out_w.weight_hi[k - 4u] = wn;
    }
  }
  weights[h] = out_w;
}
