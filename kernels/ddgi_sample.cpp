#include "kernels/ddgi_sample.h"

#include <algorithm>
#include <cmath>

#include "kernels/octahedral.h"
#include "kernels/sh.h"

namespace gibake::kernels {

ProbeWeights ddgi_probe_weights(const DdgiVolumeView& v, const float3& p, const float3& n) {
  ProbeWeights out;
  int base[3];
  float alpha[3];
  for (int a = 0; a < 3; ++a) {
    if (v.counts[a] <= 1 || v.spacing[a] <= 0.f) {
      base[a] = 0;
      alpha[a] = 0.f;
      continue;
    }
    const float g = (p.x * (a == 0) + p.y * (a == 1) + p.z * (a == 2) - v.grid_min[a]) / v.spacing[a];
    int b = static_cast<int>(std::floor(g));
    b = std::max(0, std::min(v.counts[a] - 2, b));
    base[a] = b;
    alpha[a] = saturate(g - static_cast<float>(b));
  }
  AtlasLayout layout;
  layout.counts[0] = v.counts[0];
  layout.counts[1] = v.counts[1];
  layout.counts[2] = v.counts[2];
  layout.res = v.depth_res;
  const float normal_bias = v.params[0], smooth = v.params[1];

  // Pass 1: geometry of the 8 corners, and a prefetch of the depth texels each will read, so the
  // (cache-missing) tile reads of the 8 probes overlap instead of queueing one after another.
  struct Corner {
    int probe;
    float tri, dist;
    float3 pos, dir_to_probe;
  };
  Corner corners[8];
  int count = 0;
  const int tile = v.depth_res + 2;
  for (int i = 0; i < 8; ++i) {
    const int off[3] = {i & 1, (i >> 1) & 1, (i >> 2) & 1};
    int c[3];
    for (int a = 0; a < 3; ++a) c[a] = std::min(base[a] + off[a], v.counts[a] - 1);
    const int probe = c[0] + v.counts[0] * (c[1] + v.counts[1] * c[2]);
    if (v.inactive && v.inactive[probe]) continue;
    const float tri = (off[0] ? alpha[0] : 1.f - alpha[0]) * (off[1] ? alpha[1] : 1.f - alpha[1]) *
                      (off[2] ? alpha[2] : 1.f - alpha[2]);
    if (tri <= 0.f) continue;
    Corner& k = corners[count++];
    k.probe = probe;
    k.tri = tri;
    k.pos = {v.grid_min[0] + v.spacing[0] * c[0], v.grid_min[1] + v.spacing[1] * c[1],
             v.grid_min[2] + v.spacing[2] * c[2]};
    if (v.offsets) k.pos += load3(v.offsets + 3 * probe);
    const float3 probe_to_point = p - k.pos + n * normal_bias;
    k.dist = length(probe_to_point);
    k.dir_to_probe = k.dist > 0.f ? probe_to_point * (-1.f / k.dist) : n;
    if (v.depth_tiles && k.dist > 0.f) {
      float u, w;
      encode_oct(-k.dir_to_probe, u, w);
      const int tx = std::max(0, std::min(v.depth_res, static_cast<int>((u * 0.5f + 0.5f) * v.depth_res + 0.5f)));
      const int ty = std::max(0, std::min(v.depth_res, static_cast<int>((w * 0.5f + 0.5f) * v.depth_res + 0.5f)));
      const float* t = v.depth_tiles + static_cast<size_t>(probe) * tile * tile * 2;
      __builtin_prefetch(t + (ty * tile + tx) * 2);
      __builtin_prefetch(t + ((ty + 1) * tile + tx) * 2 + 3);
    }
  }

  double sum_w = 0.0;
  for (int i = 0; i < count; ++i) {
    const Corner& k = corners[i];
    const int probe = k.probe;
    const float dist = k.dist;
    const float3 dir_to_probe = k.dir_to_probe;
    // Smooth back-face weight (seed: lerp(saturate(dot(dir,N)), wrap^2 + 0.2, smooth_backface)).
    const float3 true_dir = normalize(k.pos - p);
    const float wrap = std::max(0.0001f, (dot(true_dir, n) + 1.f) * 0.5f);
    float w = saturate(dot(dir_to_probe, n)) * (1.f - smooth) + (wrap * wrap + 0.2f) * smooth;

    // Chebyshev visibility from the depth moments.
    if ((v.depth_atlas || v.depth_tiles) && dist > 0.f) {
      float m[2];
      if (v.depth_tiles) {
        oct_sample_bilinear(v.depth_tiles + static_cast<size_t>(probe) * tile * tile * 2, tile, 2, 0, 0, v.depth_res,
                            -dir_to_probe, m);
      } else {
        int ox, oy;
        layout.tile_origin(probe, ox, oy);
        oct_sample_bilinear(v.depth_atlas, v.depth_width, 2, ox, oy, v.depth_res, -dir_to_probe, m);
      }
      if (dist > m[0]) {
        const float variance = std::max(std::fabs(m[0] * m[0] - m[1]), 1e-4f);
        const float diff = dist - m[0];
        float cheb = variance / (variance + diff * diff);
        w *= cheb * cheb * cheb;
      }
    }
    w = std::max(w, 1e-6f) * k.tri;
    out.probe[out.count] = probe;
    out.weight[out.count] = w;
    ++out.count;
    sum_w += w;
  }
  if (sum_w <= 0.0) {
    out.count = 0;
    return out;
  }
  for (int i = 0; i < out.count; ++i) out.weight[i] = static_cast<float>(out.weight[i] / sum_w);
  return out;
}

float3 ddgi_irradiance_from_weights(const float* sh, int order, const ProbeWeights& w, const float3& n) {
  const int coefs = sh_coefficient_count(order);
  float avg[kMaxShCoefficients * 3] = {};
  for (int i = 0; i < w.count; ++i) {
    const float* c = sh + static_cast<size_t>(w.probe[i]) * coefs * 3;
    for (int k = 0; k < coefs * 3; ++k) avg[k] += w.weight[i] * c[k];
  }
  const float3 e = sh_irradiance(avg, order, n);
  return {std::max(e.x, 0.f), std::max(e.y, 0.f), std::max(e.z, 0.f)};
}

float3 ddgi_sample_irradiance(const DdgiVolumeView& v, const float3& p, const float3& n) {
  return ddgi_irradiance_from_weights(v.sh, v.counts[3], ddgi_probe_weights(v, p, n), n);
}

}  // namespace gibake::kernels
