#include "kernels/integrate.h"

#include <algorithm>
#include <cmath>

#include "kernels/octahedral.h"
#include "kernels/sh.h"

namespace gibake::kernels {

std::vector<float> oct_tile_directions(int res) {
  std::vector<float> dirs(static_cast<size_t>(res) * res * 3);
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) store3(&dirs[(static_cast<size_t>(y) * res + x) * 3], oct_texel_direction(x, y, res));
  return dirs;
}

DepthConeTable build_depth_cone_table(int res, float min_weight, int bucket_res) {
  DepthConeTable t;
  t.res = res;
  t.bucket_res = bucket_res;
  t.cos_cutoff = std::pow(min_weight, 1.f / 64.f);
  t.directions = oct_tile_directions(res);
  const int count = res * res;
  const int buckets = bucket_res * bucket_res;
  t.offsets.resize(buckets + 1);
  for (int b = 0; b < buckets; ++b) {
    const int bx = b % bucket_res, by = b / bucket_res;
    t.offsets[b] = static_cast<uint32_t>(t.candidates.size());
    // Bucket centre and its angular radius (sampled over the bucket).
    const float3 c = oct_texel_direction(bx, by, bucket_res);
    float radius = 0.f;
    for (int sy = 0; sy <= 4; ++sy)
      for (int sx = 0; sx <= 4; ++sx) {
        const float u = ((bx + sx * 0.25f) / bucket_res) * 2.f - 1.f, v = ((by + sy * 0.25f) / bucket_res) * 2.f - 1.f;
        radius = std::max(radius, std::acos(clampf(dot(c, decode_oct(u, v)), -1.f, 1.f)));
      }
    const float limit = std::acos(t.cos_cutoff) + radius * 1.1f + 1e-3f;
    const float cos_limit = std::cos(std::min(limit, kPi));
    for (int j = 0; j < count; ++j)
      if (dot(c, load3(&t.directions[j * 3])) >= cos_limit) t.candidates.push_back(static_cast<uint16_t>(j));
  }
  t.offsets[buckets] = static_cast<uint32_t>(t.candidates.size());
  return t;
}

void integrate_radiance(const float* texel_dirs, int res, const RaySample* rays, int n, int sh_order,
                        float* sh_out, float* irradiance_out) {
  const int texels = res * res;
  const int coefs = sh_coefficient_count(sh_order);
  // Float accumulators in a fixed ray order: deterministic; structure-of-arrays so the texel
  // loop vectorises.
  float sh[kMaxShCoefficients * 3] = {};
  std::vector<float> tx(texels), ty(texels), tz(texels);
  for (int t = 0; t < texels; ++t) {
    tx[t] = texel_dirs[3 * t];
    ty[t] = texel_dirs[3 * t + 1];
    tz[t] = texel_dirs[3 * t + 2];
  }
  std::vector<float> ir(irradiance_out ? texels : 0, 0.f), ig(ir.size(), 0.f), ib(ir.size(), 0.f);
  for (int r = 0; r < n; ++r) {
    const float3 d = load3(rays[r].dir_depth);
    const float3 l = load3(rays[r].radiance);
    if (l.x == 0.f && l.y == 0.f && l.z == 0.f) continue;
    float y[kMaxShCoefficients];
    sh_basis(d, sh_order, y);
    for (int c = 0; c < coefs; ++c) {
      sh[c * 3 + 0] += l.x * y[c];
      sh[c * 3 + 1] += l.y * y[c];
      sh[c * 3 + 2] += l.z * y[c];
    }
    if (!irradiance_out) continue;
    float* __restrict pr = ir.data();
    float* __restrict pg = ig.data();
    float* __restrict pb = ib.data();
    const float* __restrict px = tx.data();
    const float* __restrict py = ty.data();
    const float* __restrict pz = tz.data();
    for (int t = 0; t < texels; ++t) {
      const float w = std::max(0.f, px[t] * d.x + py[t] * d.y + pz[t] * d.z);
      pr[t] += l.x * w;
      pg[t] += l.y * w;
      pb[t] += l.z * w;
    }
  }
  const float norm = n > 0 ? static_cast<float>(4.0 * 3.14159265358979323846 / n) : 0.f;
  for (int i = 0; i < coefs * 3; ++i) sh_out[i] = sh[i] * norm;
  if (irradiance_out)
    for (int t = 0; t < texels; ++t) {
      irradiance_out[t * 3 + 0] = ir[t] * norm;
      irradiance_out[t * 3 + 1] = ig[t] * norm;
      irradiance_out[t * 3 + 2] = ib[t] * norm;
    }
}

void integrate_depth(const DepthConeTable& table, const RaySample* rays, int n, float* depth_out) {
  const int res = table.res, texels = res * res;
  std::vector<float> sum(static_cast<size_t>(texels) * 3, 0.f);  // w*d, w*d^2, w
  for (int r = 0; r < n; ++r) {
    const float3 d = load3(rays[r].dir_depth);
    const float depth = rays[r].dir_depth[3];
    int tx, ty;
    oct_texel_of(d, table.bucket_res, tx, ty);
    const int cell = ty * table.bucket_res + tx;
    for (uint32_t k = table.offsets[cell]; k < table.offsets[cell + 1]; ++k) {
      const int t = table.candidates[k];
      const float c = dot(load3(&table.directions[t * 3]), d);
      if (c < table.cos_cutoff) continue;
      // pow(c, 64) by repeated squaring.
      float w = c * c; w *= w; w *= w; w *= w; w *= w; w *= w;
      sum[t * 3 + 0] += w * depth;
      sum[t * 3 + 1] += w * depth * depth;
      sum[t * 3 + 2] += w;
    }
  }
  for (int t = 0; t < texels; ++t) {
    if (sum[t * 3 + 2] > 0.f) {
      depth_out[t * 2 + 0] = sum[t * 3 + 0] / sum[t * 3 + 2];
      depth_out[t * 2 + 1] = sum[t * 3 + 1] / sum[t * 3 + 2];
      continue;
    }
    // Too few rays for this cone: take the ray closest in direction.
    const float3 a = load3(&table.directions[t * 3]);
    float best = -2.f, depth = 0.f;
    for (int r = 0; r < n; ++r) {
      const float c = dot(a, load3(rays[r].dir_depth));
      if (c > best) { best = c; depth = rays[r].dir_depth[3]; }
    }
    depth_out[t * 2 + 0] = depth;
    depth_out[t * 2 + 1] = depth * depth;
  }
}

}  // namespace gibake::kernels
