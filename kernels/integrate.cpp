#include "kernels/integrate.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
  t.dir_x.resize(count);
  t.dir_y.resize(count);
  t.dir_z.resize(count);
  for (int j = 0; j < count; ++j) {
    t.dir_x[j] = t.directions[j * 3];
    t.dir_y[j] = t.directions[j * 3 + 1];
    t.dir_z[j] = t.directions[j * 3 + 2];
  }
  return t;
}

namespace {

// Irradiance texels [t0, t0+count) of one tile, count <= kChunk: distinct local arrays (so the
// compiler knows they do not alias and vectorises the texel loop), no heap.
constexpr int kChunk = 256;
void irradiance_chunk(const float* texel_dirs, int t0, int count, const RaySample* rays, int n, float norm,
                      float* irradiance_out) {
  alignas(64) float tx[kChunk], ty[kChunk], tz[kChunk], ir[kChunk], ig[kChunk], ib[kChunk];
  for (int t = 0; t < count; ++t) {
    tx[t] = texel_dirs[3 * (t0 + t)];
    ty[t] = texel_dirs[3 * (t0 + t) + 1];
    tz[t] = texel_dirs[3 * (t0 + t) + 2];
    ir[t] = ig[t] = ib[t] = 0.f;
  }
  for (int r = 0; r < n; ++r) {
    const float3 d = load3(rays[r].dir_depth);
    const float3 l = load3(rays[r].radiance);
    if (l.x == 0.f && l.y == 0.f && l.z == 0.f) continue;
    for (int t = 0; t < count; ++t) {
      const float w = std::max(0.f, tx[t] * d.x + ty[t] * d.y + tz[t] * d.z);
      ir[t] += l.x * w;
      ig[t] += l.y * w;
      ib[t] += l.z * w;
    }
  }
  for (int t = 0; t < count; ++t) {
    irradiance_out[(t0 + t) * 3 + 0] = ir[t] * norm;
    irradiance_out[(t0 + t) * 3 + 1] = ig[t] * norm;
    irradiance_out[(t0 + t) * 3 + 2] = ib[t] * norm;
  }
}

}  // namespace

void integrate_radiance(const float* texel_dirs, int res, const RaySample* rays, int n, int sh_order,
                        float* sh_out, float* irradiance_out, int norm_count) {
  const int texels = res * res;
  const int coefs = sh_coefficient_count(sh_order);
  // Float accumulators in a fixed ray order: deterministic (every texel and coefficient sums its
  // rays in ray order); structure-of-arrays so the texel loop vectorises.
  float sh[kMaxShCoefficients * 3] = {};
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
  }
  const int count = norm_count > 0 ? norm_count : n;
  const float norm = count > 0 ? static_cast<float>(4.0 * 3.14159265358979323846 / count) : 0.f;
  for (int i = 0; i < coefs * 3; ++i) sh_out[i] = sh[i] * norm;
  if (irradiance_out)
    for (int t0 = 0; t0 < texels; t0 += kChunk)
      irradiance_chunk(texel_dirs, t0, std::min(kChunk, texels - t0), rays, n, norm, irradiance_out);
}

namespace {

// Adds one ray's depth to the cone of every texel around its direction: w*d, w*d^2 and w per
// texel in `sum`, w = cos^64 within the table's cut-off.
inline void add_depth_ray(const DepthConeTable& table, const RaySample& ray, float* sum) {
  // Texel directions as structure-of-arrays (3 KB: stays in L1 while the rays jump between buckets).
  const float* __restrict cx = table.dir_x.data();
  const float* __restrict cy = table.dir_y.data();
  const float* __restrict cz = table.dir_z.data();
  const uint16_t* __restrict cand = table.candidates.data();
  const uint32_t* __restrict offs = table.offsets.data();
  const float cos_cutoff = table.cos_cutoff;
  // Branch-free over a bucket's candidates: outside the cone the weight is exactly +0, and
  // adding +0 to a non-negative sum changes nothing, so the result equals skipping those texels.
  const float3 d = load3(ray.dir_depth);
  const float depth = ray.dir_depth[3];
  int tx, ty;
  oct_texel_of(d, table.bucket_res, tx, ty);
  const int cell = ty * table.bucket_res + tx;
  uint32_t k = offs[cell];
  const uint32_t end = offs[cell + 1];
#if defined(__SSE2__)
  // Four candidates at a time: the same per-lane operations as the scalar loop below (SSE
  // multiply and add are IEEE-exact per lane), then the sums in candidate order.
  const __m128 vdx = _mm_set1_ps(d.x), vdy = _mm_set1_ps(d.y), vdz = _mm_set1_ps(d.z);
  const __m128 vdepth = _mm_set1_ps(depth), vcut = _mm_set1_ps(cos_cutoff);
  for (; k + 4 <= end; k += 4) {
    const int t0 = cand[k], t1 = cand[k + 1], t2 = cand[k + 2], t3 = cand[k + 3];
    const __m128 x = _mm_setr_ps(cx[t0], cx[t1], cx[t2], cx[t3]);
    const __m128 y = _mm_setr_ps(cy[t0], cy[t1], cy[t2], cy[t3]);
    const __m128 z = _mm_setr_ps(cz[t0], cz[t1], cz[t2], cz[t3]);
    const __m128 c = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, vdx), _mm_mul_ps(y, vdy)), _mm_mul_ps(z, vdz));
    __m128 w = _mm_mul_ps(c, c);
    w = _mm_mul_ps(w, w);
    w = _mm_mul_ps(w, w);
    w = _mm_mul_ps(w, w);
    w = _mm_mul_ps(w, w);
    w = _mm_mul_ps(w, w);
    w = _mm_and_ps(w, _mm_cmpge_ps(c, vcut));
    const __m128 wd = _mm_mul_ps(w, vdepth);
    const __m128 wdd = _mm_mul_ps(wd, vdepth);
    alignas(16) float a[4], b[4], e[4];
    _mm_store_ps(a, wd);
    _mm_store_ps(b, wdd);
    _mm_store_ps(e, w);
    const int ts[4] = {t0, t1, t2, t3};
    for (int l = 0; l < 4; ++l) {
      float* st = sum + ts[l] * 3;
      st[0] += a[l];
      st[1] += b[l];
      st[2] += e[l];
    }
  }
#endif
  for (; k < end; ++k) {
    const int t = cand[k];
    const float c = cx[t] * d.x + cy[t] * d.y + cz[t] * d.z;
    // pow(c, 64) by repeated squaring.
    float w = c * c;
    w *= w;
    w *= w;
    w *= w;
    w *= w;
    w *= w;
    // w = c < cos_cutoff ? 0 : w, as a mask (no branch to mispredict).
    uint32_t bits;
    std::memcpy(&bits, &w, 4);
    bits &= 0u - static_cast<uint32_t>(c >= cos_cutoff);
    std::memcpy(&w, &bits, 4);
    float* st = sum + t * 3;
    st[0] += w * depth;
    st[1] += w * depth * depth;
    st[2] += w;
  }
}

// Each texel's mean depth and mean squared depth over its cone; a texel whose cone no ray reached
// (too few rays) takes the depth of the ray closest in direction.
void resolve_depth_moments(const DepthConeTable& table, const RaySample* rays, int n, const float* sum,
                           float* depth_out) {
  const int texels = table.res * table.res;
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

}  // namespace

void integrate_depth(const DepthConeTable& table, const RaySample* rays, int n, float* depth_out) {
  const int texels = table.res * table.res;
  // w*d, w*d^2, w per texel; on the stack for the usual 16x16 tile.
  constexpr int kStackTexels = 1024;
  float stack_sum[3 * kStackTexels];
  std::vector<float> heap_sum;
  float* sum = stack_sum;
  if (texels > kStackTexels) {
    heap_sum.resize(size_t(3) * texels);
    sum = heap_sum.data();
  }
  std::fill(sum, sum + size_t(3) * texels, 0.f);
  for (int r = 0; r < n; ++r) add_depth_ray(table, rays[r], sum);
  resolve_depth_moments(table, rays, n, sum, depth_out);
}

}  // namespace gibake::kernels
