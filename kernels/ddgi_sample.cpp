#include "kernels/ddgi_sample.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "kernels/octahedral.h"
#include "kernels/sh.h"

namespace gibake::kernels {

// The grid cell holding p (its lowest corner probe) and p's trilinear position inside it.
static void base_cell(const DdgiVolumeView& v, const float3& p, int base[3], float alpha[3]) {
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
}

// Corner i of the cell (bit 0: +x, bit 1: +y, bit 2: +z): its grid coordinate, probe index and
// trilinear weight. False when the probe is inactive or the weight is zero.
static bool cell_corner(const DdgiVolumeView& v, const int base[3], const float alpha[3], int i, int c[3],
                        int& probe, float& tri) {
  const int off[3] = {i & 1, (i >> 1) & 1, (i >> 2) & 1};
  for (int a = 0; a < 3; ++a) c[a] = std::min(base[a] + off[a], v.counts[a] - 1);
  probe = c[0] + v.counts[0] * (c[1] + v.counts[1] * c[2]);
  if (v.inactive && v.inactive[probe]) return false;
  tri = (off[0] ? alpha[0] : 1.f - alpha[0]) * (off[1] ? alpha[1] : 1.f - alpha[1]) *
        (off[2] ? alpha[2] : 1.f - alpha[2]);
  return tri > 0.f;
}

static ProbeWeights probe_weights_scalar(const DdgiVolumeView& v, const float3& p, const float3& n) {
  ProbeWeights out;
  int base[3];
  float alpha[3];
  base_cell(v, p, base, alpha);
  AtlasLayout layout;
  layout.counts[0] = v.counts[0];
  layout.counts[1] = v.counts[1];
  layout.counts[2] = v.counts[2];
  layout.res = v.depth_res;
  layout.planes_per_row = v.atlas_planes_per_row;
  const float normal_bias = v.params[0], smooth = v.params[1];

  // Pass 1: geometry of the 8 corners, and a prefetch of the depth texels each will read, so the
  // (cache-missing) tile reads of the 8 probes overlap instead of queueing one after another.
  struct Corner {
    int probe;
    float tri, dist;
    float u, w;  // encode_oct(-dir_to_probe), when the depth tiles are sampled
    float3 pos, dir_to_probe;
  };
  Corner corners[8];
  int count = 0;
  const int tile = v.depth_res + 2;
  for (int i = 0; i < 8; ++i) {
    int c[3], probe;
    float tri;
    if (!cell_corner(v, base, alpha, i, c, probe, tri)) continue;
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
      float& u = k.u;
      float& w = k.w;
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
    // Smooth back-face weight (DDGI's rule: lerp(saturate(dot(dir,N)), wrap^2 + 0.2, smooth_backface)).
    const float3 true_dir = normalize(k.pos - p);
    const float wrap = std::max(0.0001f, (dot(true_dir, n) + 1.f) * 0.5f);
    float w = saturate(dot(dir_to_probe, n)) * (1.f - smooth) + (wrap * wrap + 0.2f) * smooth;

    // Chebyshev visibility from the depth moments.
    if ((v.depth_atlas || v.depth_tiles) && dist > 0.f) {
      float m[2];
      if (v.depth_tiles) {
        oct_sample_bilinear_uv(v.depth_tiles + static_cast<size_t>(probe) * tile * tile * 2, tile, 2, 0, 0,
                               v.depth_res, k.u, k.w, m);
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

#if defined(__SSE2__)
namespace {

// Lane-wise versions of the scalar helpers with the scalar code's exact semantics (operand order
// of every + and *, NaN behaviour of std::max / saturate / clampf): SSE arithmetic, sqrt and
// division are IEEE-exact per lane, so each lane reproduces the scalar result bit for bit.
inline __m128 sel(__m128 mask, __m128 a, __m128 b) {  // mask ? a : b
  return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
// std::max(c, x) == (c < x) ? x : c
inline __m128 max_c_x(__m128 c, __m128 x) { return sel(_mm_cmplt_ps(c, x), x, c); }
// std::max(x, c) == (x < c) ? c : x
inline __m128 max_x_c(__m128 x, __m128 c) { return sel(_mm_cmplt_ps(x, c), c, x); }
// clampf(v, lo, hi) == v < lo ? lo : (v > hi ? hi : v)
inline __m128 clamp_v(__m128 v, __m128 lo, __m128 hi) {
  return sel(_mm_cmplt_ps(v, lo), lo, sel(_mm_cmpgt_ps(v, hi), hi, v));
}
inline __m128 absv(__m128 v) { return _mm_and_ps(v, _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF))); }
// floor for |v| < 2^31 (texel coordinates), as std::floor.
inline __m128i floor_i(__m128 v) {
  const __m128i t = _mm_cvttps_epi32(v);
  const __m128 tf = _mm_cvtepi32_ps(t);
  return _mm_add_epi32(t, _mm_castps_si128(_mm_cmpgt_ps(tf, v)));  // -1 where trunc > v
}

}  // namespace

// Same as probe_weights_scalar with depth tiles: the per-corner geometry, back-face weight,
// octahedral lookup coordinates and Chebyshev test for 4 corners at a time.
static ProbeWeights probe_weights_sse(const DdgiVolumeView& v, const float3& p, const float3& n) {
  ProbeWeights out;
  int base[3];
  float alpha[3];
  base_cell(v, p, base, alpha);
  const float normal_bias = v.params[0], smooth = v.params[1];
  alignas(16) float px_[8], py_[8], pz_[8], tri_[8];
  int probe_[8];
  int count = 0;
  for (int i = 0; i < 8; ++i) {
    int c[3], probe;
    float tri;
    if (!cell_corner(v, base, alpha, i, c, probe, tri)) continue;
    float3 pos = {v.grid_min[0] + v.spacing[0] * c[0], v.grid_min[1] + v.spacing[1] * c[1],
                  v.grid_min[2] + v.spacing[2] * c[2]};
    if (v.offsets) pos += load3(v.offsets + 3 * probe);
    probe_[count] = probe;
    tri_[count] = tri;
    px_[count] = pos.x;
    py_[count] = pos.y;
    pz_[count] = pos.z;
    ++count;
  }
  for (int i = count; i < 8; ++i) {  // padding lanes: finite values, results unused
    probe_[i] = count ? probe_[0] : 0;
    tri_[i] = 0.f;
    px_[i] = p.x + 1.f;
    py_[i] = p.y;
    pz_[i] = p.z;
  }
  alignas(16) float w_[8];
  const int tile = v.depth_res + 2;
  const float res = static_cast<float>(v.depth_res);
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f), half = _mm_set1_ps(0.5f);
  const __m128 nx = _mm_set1_ps(n.x), ny = _mm_set1_ps(n.y), nz = _mm_set1_ps(n.z);
  const __m128 ppx = _mm_set1_ps(p.x), ppy = _mm_set1_ps(p.y), ppz = _mm_set1_ps(p.z);
  const __m128 bias = _mm_set1_ps(normal_bias);
  // Two phases: the geometry of all (up to 8) corners first, prefetching the two texel rows each
  // will read; then the depth lookups and Chebyshev test. The tile reads of the 8 probes (mostly
  // cache misses) then overlap instead of waiting group by group.
  struct Group {
    __m128 dist, dpos, w, fax, fay;
    alignas(16) int xi[4], yi[4];
  };
  Group groups[2];
  for (int g = 0; g < count; g += 4) {
    Group& gr = groups[g / 4];
    const __m128 kx = _mm_load_ps(px_ + g), ky = _mm_load_ps(py_ + g), kz = _mm_load_ps(pz_ + g);
    // probe_to_point = (p - pos) + n * bias; dist = length; dir_to_probe = dist > 0 ? ptp * (-1/dist) : n
    const __m128 tx = _mm_add_ps(_mm_sub_ps(ppx, kx), _mm_mul_ps(nx, bias));
    const __m128 ty = _mm_add_ps(_mm_sub_ps(ppy, ky), _mm_mul_ps(ny, bias));
    const __m128 tz = _mm_add_ps(_mm_sub_ps(ppz, kz), _mm_mul_ps(nz, bias));
    const __m128 dist =
        _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, tx), _mm_mul_ps(ty, ty)), _mm_mul_ps(tz, tz)));
    const __m128 dpos = _mm_cmpgt_ps(dist, zero);
    const __m128 inv = _mm_div_ps(_mm_set1_ps(-1.f), dist);
    const __m128 dx = sel(dpos, _mm_mul_ps(tx, inv), nx);
    const __m128 dy = sel(dpos, _mm_mul_ps(ty, inv), ny);
    const __m128 dz = sel(dpos, _mm_mul_ps(tz, inv), nz);
    // true_dir = normalize(pos - p)
    const __m128 ax = _mm_sub_ps(kx, ppx), ay = _mm_sub_ps(ky, ppy), az = _mm_sub_ps(kz, ppz);
    const __m128 al =
        _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, ax), _mm_mul_ps(ay, ay)), _mm_mul_ps(az, az)));
    const __m128 apos = _mm_cmpgt_ps(al, zero);
    const __m128 ainv = _mm_div_ps(one, al);
    const __m128 ux = _mm_and_ps(apos, _mm_mul_ps(ax, ainv));
    const __m128 uy = _mm_and_ps(apos, _mm_mul_ps(ay, ainv));
    const __m128 uz = _mm_and_ps(apos, _mm_mul_ps(az, ainv));
    const __m128 tdn = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ux, nx), _mm_mul_ps(uy, ny)), _mm_mul_ps(uz, nz));
    const __m128 wrap = max_c_x(_mm_set1_ps(0.0001f), _mm_mul_ps(_mm_add_ps(tdn, one), half));
    const __m128 ddn = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, nx), _mm_mul_ps(dy, ny)), _mm_mul_ps(dz, nz));
    const __m128 sat = sel(_mm_cmplt_ps(ddn, zero), zero, sel(_mm_cmpgt_ps(ddn, one), one, ddn));
    __m128 w = _mm_add_ps(_mm_mul_ps(sat, _mm_set1_ps(1.f - smooth)),
                          _mm_mul_ps(_mm_add_ps(_mm_mul_ps(wrap, wrap), _mm_set1_ps(0.2f)), _mm_set1_ps(smooth)));
    // encode_oct(-dir_to_probe)
    const __m128 signbit = _mm_castsi128_ps(_mm_set1_epi32(static_cast<int>(0x80000000u)));
    const __m128 ex = _mm_xor_ps(dx, signbit), ey = _mm_xor_ps(dy, signbit), ez = _mm_xor_ps(dz, signbit);
    const __m128 einv = _mm_div_ps(one, _mm_add_ps(_mm_add_ps(absv(ex), absv(ey)), absv(ez)));
    const __m128 ox = _mm_mul_ps(ex, einv), oy = _mm_mul_ps(ey, einv);
    const __m128 sx = sel(_mm_cmpge_ps(ox, zero), one, _mm_set1_ps(-1.f));
    const __m128 sy = sel(_mm_cmpge_ps(oy, zero), one, _mm_set1_ps(-1.f));
    const __m128 fold = _mm_cmplt_ps(ez, zero);
    const __m128 u = sel(fold, _mm_mul_ps(_mm_sub_ps(one, absv(oy)), sx), ox);
    const __m128 vv = sel(fold, _mm_mul_ps(_mm_sub_ps(one, absv(ox)), sy), oy);
    // oct_sample_bilinear_uv coordinates
    const __m128 vres = _mm_set1_ps(res);
    const __m128 fx = _mm_sub_ps(_mm_add_ps(one, _mm_mul_ps(_mm_add_ps(_mm_mul_ps(u, half), half), vres)), half);
    const __m128 fy = _mm_sub_ps(_mm_add_ps(one, _mm_mul_ps(_mm_add_ps(_mm_mul_ps(vv, half), half), vres)), half);
    __m128i x0 = floor_i(fx), y0 = floor_i(fy);
    const __m128i ires = _mm_set1_epi32(v.depth_res), izero = _mm_setzero_si128();
    // clamp to [0, res]
    x0 = _mm_andnot_si128(_mm_cmplt_epi32(x0, izero), x0);
    y0 = _mm_andnot_si128(_mm_cmplt_epi32(y0, izero), y0);
    const __m128i xg = _mm_cmpgt_epi32(x0, ires), yg = _mm_cmpgt_epi32(y0, ires);
    x0 = _mm_or_si128(_mm_and_si128(xg, ires), _mm_andnot_si128(xg, x0));
    y0 = _mm_or_si128(_mm_and_si128(yg, ires), _mm_andnot_si128(yg, y0));
    const __m128 fax = clamp_v(_mm_sub_ps(fx, _mm_cvtepi32_ps(x0)), zero, one);
    const __m128 fay = clamp_v(_mm_sub_ps(fy, _mm_cvtepi32_ps(y0)), zero, one);
    _mm_store_si128(reinterpret_cast<__m128i*>(gr.xi), x0);
    _mm_store_si128(reinterpret_cast<__m128i*>(gr.yi), y0);
    gr.dist = dist;
    gr.dpos = dpos;
    gr.w = w;
    gr.fax = fax;
    gr.fay = fay;
    for (int l = 0; l < 4; ++l) {
      const float* t00 = v.depth_tiles + static_cast<size_t>(probe_[g + l]) * tile * tile * 2 +
                         (gr.yi[l] * tile + gr.xi[l]) * 2;
      __builtin_prefetch(t00);
      __builtin_prefetch(t00 + 3);
      __builtin_prefetch(t00 + tile * 2);
      __builtin_prefetch(t00 + tile * 2 + 3);
    }
  }
  for (int g = 0; g < count; g += 4) {
    const Group& gr = groups[g / 4];
    const __m128 dist = gr.dist, dpos = gr.dpos, fax = gr.fax, fay = gr.fay;
    __m128 w = gr.w;
    alignas(16) float a0[4], b0[4], c0[4], d0[4], a1[4], b1[4], c1[4], d1[4];
    for (int l = 0; l < 4; ++l) {
      const float* t = v.depth_tiles + static_cast<size_t>(probe_[g + l]) * tile * tile * 2;
      const float* t00 = t + (gr.yi[l] * tile + gr.xi[l]) * 2;
      const float* t01 = t00 + tile * 2;
      a0[l] = t00[0]; a1[l] = t00[1];
      b0[l] = t00[2]; b1[l] = t00[3];
      c0[l] = t01[0]; c1[l] = t01[1];
      d0[l] = t01[2]; d1[l] = t01[3];
    }
    auto bilerp = [&](const float* t00, const float* t10, const float* t01, const float* t11) {
      const __m128 q00 = _mm_load_ps(t00), q10 = _mm_load_ps(t10), q01 = _mm_load_ps(t01), q11 = _mm_load_ps(t11);
      const __m128 ra = _mm_add_ps(q00, _mm_mul_ps(_mm_sub_ps(q10, q00), fax));
      const __m128 rb = _mm_add_ps(q01, _mm_mul_ps(_mm_sub_ps(q11, q01), fax));
      return _mm_add_ps(ra, _mm_mul_ps(_mm_sub_ps(rb, ra), fay));
    };
    const __m128 m0 = bilerp(a0, b0, c0, d0), m1 = bilerp(a1, b1, c1, d1);
    // Chebyshev visibility where dist > 0 and dist > mean
    const __m128 var = max_x_c(absv(_mm_sub_ps(_mm_mul_ps(m0, m0), m1)), _mm_set1_ps(1e-4f));
    const __m128 diff = _mm_sub_ps(dist, m0);
    const __m128 cheb = _mm_div_ps(var, _mm_add_ps(var, _mm_mul_ps(diff, diff)));
    const __m128 wc = _mm_mul_ps(w, _mm_mul_ps(_mm_mul_ps(cheb, cheb), cheb));
    w = sel(_mm_and_ps(dpos, _mm_cmpgt_ps(dist, m0)), wc, w);
    w = _mm_mul_ps(max_x_c(w, _mm_set1_ps(1e-6f)), _mm_load_ps(tri_ + g));
    _mm_store_ps(w_ + g, w);
  }
  double sum_w = 0.0;
  for (int i = 0; i < count; ++i) {
    out.probe[i] = probe_[i];
    out.weight[i] = w_[i];
    sum_w += w_[i];
  }
  out.count = count;
  if (sum_w <= 0.0) {
    out.count = 0;
    return out;
  }
  for (int i = 0; i < out.count; ++i) out.weight[i] = static_cast<float>(out.weight[i] / sum_w);
  return out;
}
#endif

ProbeWeights ddgi_probe_weights(const DdgiVolumeView& v, const float3& p, const float3& n) {
#if defined(__SSE2__)
  if (v.depth_tiles) return probe_weights_sse(v, p, n);
#endif
  return probe_weights_scalar(v, p, n);
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
