// CPU DDGI sampling (DDGI probe sampling): 8 probes, trilinear, smooth backface,
// Chebyshev visibility from the depth-moment atlas, the probes' irradiance atlas texels (or their
// SH) weighted: irradiance E(n) in lux.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "gibake/loader.hpp"

namespace gibake::loader {
namespace {

constexpr float kPi = 3.14159265358979323846f;

float dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
float length(const Vec3& a) { return std::sqrt(dot(a, a)); }
Vec3 normalize(const Vec3& a) {
  const float l = length(a);
  if (!(l > 0.f) || !std::isfinite(l)) return {0.f, 0.f, 1.f};
  return {a[0] / l, a[1] / l, a[2] / l};
}
float saturate(float v) { return v < 0.f ? 0.f : (v > 1.f ? 1.f : v); }

}  // namespace

Rgb sh_irradiance(const float* sh, uint32_t coefficients, const Vec3& n) {
  const float x = n[0], y = n[1], z = n[2];
  const float a0 = kPi, a1 = 2.f * kPi / 3.f, a2 = kPi / 4.f;
  float basis[9] = {a0 * 0.282095f,
                    a1 * 0.488603f * y,
                    a1 * 0.488603f * z,
                    a1 * 0.488603f * x,
                    a2 * 1.092548f * x * y,
                    a2 * 1.092548f * y * z,
                    a2 * 0.315392f * (3.f * z * z - 1.f),
                    a2 * 1.092548f * x * z,
                    a2 * 0.546274f * (x * x - y * y)};
  Rgb out{0.f, 0.f, 0.f};
  const uint32_t count = std::min<uint32_t>(coefficients, 9);
  for (uint32_t c = 0; c < count; ++c)
    for (int k = 0; k < 3; ++k) out[k] += basis[c] * sh[c * 3 + k];
  for (float& v : out) v = v > 0.f ? v : 0.f;  // also maps NaN to 0
  return out;
}

std::array<float, 2> encode_oct(const Vec3& d) {
  const float l1 = std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]);
  if (!(l1 > 0.f)) return {0.f, 0.f};
  float u = d[0] / l1, v = d[1] / l1;
  if (d[2] < 0.f) {
    const float su = u >= 0.f ? 1.f : -1.f, sv = v >= 0.f ? 1.f : -1.f;
    const float nu = (1.f - std::fabs(v)) * su, nv = (1.f - std::fabs(u)) * sv;
    u = nu;
    v = nv;
  }
  return {u, v};
}

Rgb DdgiVolume::sh_irradiance(uint32_t probe, const Vec3& n) const {
  float coefficients[27] = {};
  if (probe >= desc_.probe_count) return {0.f, 0.f, 0.f};
  sh_probe(probe, coefficients);
  return loader::sh_irradiance(coefficients, desc_.sh_coefficients, n);
}

namespace {

struct Moments {
  float mean = 0.f, mean2 = 0.f;
};

// The 4 texels that bilinear filtering reads in one probe's bordered tile of `interior` texels in
// direction `dir`, clamped to the tile, in order with their weights.
struct TileTexels {
  uint32_t x[4], y[4];  // atlas coordinates
  uint32_t i[4];        // index in the tile, row by row, border included
  float w[4];
};

// `cell`: the probe's DdgiVolume::tile_cell.
TileTexels tile_texels(const DdgiVolume& v, const std::array<uint32_t, 2>& cell, uint32_t interior, const Vec3& dir) {
  const gibake_ddgi_volume& d = v.desc();
  const float tile = float(interior);
  const uint32_t side = interior + 2 * d.tile_border;
  const uint32_t origin[2] = {cell[0] * side, cell[1] * side};  // DdgiVolume::tile_origin
  const float ox = float(origin[0]), oy = float(origin[1]);
  const std::array<float, 2> oct = encode_oct(dir);
  // Continuous texel coordinates (texel centres at +0.5) inside the tile interior.
  const float fx = ox + float(d.tile_border) + (oct[0] * 0.5f + 0.5f) * tile - 0.5f;
  const float fy = oy + float(d.tile_border) + (oct[1] * 0.5f + 0.5f) * tile - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float tx = fx - x0f, ty = fy - y0f;
  const float lo_x = ox, hi_x = ox + float(side - 1), lo_y = oy, hi_y = oy + float(side - 1);
  TileTexels t;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const int k = 2 * j + i;
      t.x[k] = uint32_t(std::clamp(x0f + float(i), lo_x, hi_x));
      t.y[k] = uint32_t(std::clamp(y0f + float(j), lo_y, hi_y));
      t.w[k] = (i ? tx : 1.f - tx) * (j ? ty : 1.f - ty);
      t.i[k] = (t.y[k] - origin[1]) * side + (t.x[k] - origin[0]);
    }
  }
  return t;
}

// Asks the memory system for the cache lines of the texels in a probe's probe-major block (a
// hint: no value depends on it). Sampling reads 8 scattered tiles from each atlas; asking for all
// of them first lets their loads overlap instead of waiting for one after another.
void prefetch_texels(const DdgiVolume& v, uint32_t probe, bool depth, const TileTexels& t) {
#if defined(__GNUC__) || defined(__clang__)
  const uint8_t* block = v.probe_tile(probe, depth);
  if (!block) return;
  const size_t texel_bytes = size_t(depth ? 2 : 3) * v.probe_tile_element_bytes(depth);
  for (int k = 0; k < 4; ++k) __builtin_prefetch(block + t.i[k] * texel_bytes);
#else
  (void)v, (void)probe, (void)depth, (void)t;
#endif
}

// Element k of texel i of a probe-major block (DdgiVolume::ProbeTiles) of `channels`-element
// texels of `bytes` bytes each: what the atlas holds there, decoded the same way.
float tile_element(const uint8_t* block, uint32_t i, uint32_t channels, uint32_t k, uint32_t bytes) {
  const uint8_t* at = block + (size_t(i) * channels + k) * bytes;
  if (bytes == 2) {
    uint16_t h;
    std::memcpy(&h, at, 2);
    return half_to_float(h);
  }
  float f;
  std::memcpy(&f, at, 4);
  return f;
}

Moments sample_depth(const DdgiVolume& v, uint32_t probe, const TileTexels& t) {
  Moments m;
  if (const uint8_t* block = v.probe_tile(probe, true)) {
    const uint32_t bytes = v.probe_tile_element_bytes(true);
    for (int k = 0; k < 4; ++k) {
      m.mean += t.w[k] * tile_element(block, t.i[k], 2, 0, bytes);
      m.mean2 += t.w[k] * tile_element(block, t.i[k], 2, 1, bytes);
    }
    return m;
  }
  for (int k = 0; k < 4; ++k) {
    const std::array<float, 2> d = v.depth_texel(t.x[k], t.y[k]);
    m.mean += t.w[k] * d[0];
    m.mean2 += t.w[k] * d[1];
  }
  return m;
}

Rgb tile_irradiance(const DdgiVolume& v, uint32_t probe, const TileTexels& t) {
  Rgb e{0.f, 0.f, 0.f};
  if (const uint8_t* block = v.probe_tile(probe, false)) {
    const uint32_t bytes = v.probe_tile_element_bytes(false);
    for (int j = 0; j < 4; ++j)
      for (uint32_t k = 0; k < 3; ++k) e[k] += t.w[j] * tile_element(block, t.i[j], 3, k, bytes);
    return e;
  }
  for (int j = 0; j < 4; ++j) {
    const std::array<float, 4> texel = v.irradiance_texel(t.x[j], t.y[j]);
    for (int k = 0; k < 3; ++k) e[k] += t.w[j] * texel[k];
  }
  return e;
}

float chebyshev(const Moments& m, float distance, float variance_floor) {
  if (!(distance > m.mean)) return 1.f;  // in front of the mean occluder (also NaN-safe)
  // |mean^2 - mean2| and the cube follow kernels/ddgi_sample.cpp (RTXGI): the bake's own
  // multi-bounce sampling and this runtime sampler weight probes identically.
  const float variance = std::max(std::fabs(m.mean * m.mean - m.mean2), variance_floor);
  const float delta = distance - m.mean;
  const float c = variance / (variance + delta * delta);
  return c * c * c;
}

// DdgiVolume::probe_weights; with `irradiance` set, also each weighed probe's irradiance texels
// for n (when the volume has an irradiance atlas and the options read it).
uint32_t weigh_probes(const DdgiVolume& v, const Vec3& p, const Vec3& n, const SampleOptions& o, ProbeWeight out[8],
                      TileTexels irradiance[8]) {
  if (!v.has_sh()) return 0;
  const gibake_ddgi_volume& d = v.desc();
  std::array<int32_t, 3> base{};
  Vec3 alpha{};
  for (int a = 0; a < 3; ++a) {
    const int32_t last = d.counts[a] - 1;
    if (last == 0 || !(d.spacing[a] > 0.f)) continue;
    const float g = (p[a] - d.grid_min[a]) / d.spacing[a];
    const float gc = std::clamp(std::isfinite(g) ? g : 0.f, 0.f, float(last));
    base[a] = std::min(int32_t(std::floor(gc)), last);
    alpha[a] = saturate(gc - float(base[a]));
  }
  const bool visibility = o.use_visibility && v.has_depth();
  const bool atlas = irradiance && o.use_irradiance_atlas && v.has_irradiance();  // texels wanted
  float min_spacing = 0.f;
  for (int a = 0; a < 3; ++a)
    if (d.counts[a] > 1 && d.spacing[a] > 0.f)
      min_spacing = min_spacing > 0.f ? std::min(min_spacing, d.spacing[a]) : d.spacing[a];
  const float bias = std::max(o.normal_bias, o.normal_bias_cells * min_spacing);
  const Vec3 biased{p[0] + n[0] * bias, p[1] + n[1] * bias, p[2] + n[2] * bias};
  // First every active corner's probe and the texels it will read (their loads started), then
  // the weights in corner order.
  struct Corner {
    int i;
    uint32_t index;
    Vec3 probe_pos, probe_to_point;
    TileTexels depth, irradiance;
  };
  Corner corners[8];
  int active = 0;
  for (int i = 0; i < 8; ++i) {
    std::array<int32_t, 3> c{};
    for (int a = 0; a < 3; ++a) c[a] = std::min(base[a] + ((i >> a) & 1), d.counts[a] - 1);
    const uint32_t index = uint32_t(c[0] + d.counts[0] * (c[1] + d.counts[1] * c[2]));
    if (v.state(index) == GIBAKE_PROBE_INACTIVE) continue;
    Corner& k = corners[active++];
    k.i = i;
    k.index = index;
    const Vec3 rest = v.probe_rest_position(c), offset = v.offset(index);  // DdgiVolume::probe_position
    k.probe_pos = {rest[0] + offset[0], rest[1] + offset[1], rest[2] + offset[2]};
    k.probe_to_point = sub(biased, k.probe_pos);
    const std::array<uint32_t, 2> cell = (visibility || atlas) ? v.tile_cell(c) : std::array<uint32_t, 2>{};
    if (visibility) {
      k.depth = tile_texels(v, cell, d.depth_tile, normalize(k.probe_to_point));
      prefetch_texels(v, index, true, k.depth);
    }
    if (atlas) {
      k.irradiance = tile_texels(v, cell, d.irradiance_tile, n);
      prefetch_texels(v, index, false, k.irradiance);
    }
  }
  uint32_t count = 0;
  for (int j = 0; j < active; ++j) {
    const Corner& k = corners[j];
    const std::array<int32_t, 3> off{k.i & 1, (k.i >> 1) & 1, (k.i >> 2) & 1};
    const Vec3& probe_to_point = k.probe_to_point;
    const Vec3 dir = normalize({-probe_to_point[0], -probe_to_point[1], -probe_to_point[2]});
    const Vec3 true_dir = normalize(sub(k.probe_pos, p));
    ProbeWeight w;
    w.probe = k.index;
    w.distance = length(probe_to_point);
    const float hard = saturate(dot(dir, n));
    const float facing = dot(true_dir, n);  // < 0: the probe lies behind the surface's tangent plane
    const float wrap = std::max(0.0001f, (facing + 1.f) * 0.5f);
    w.backface = hard + (wrap * wrap + 0.2f - hard) * o.smooth_backface;
    if (o.behind_fade > 0.f) w.backface *= saturate(1.f + facing / o.behind_fade);
    if (visibility) w.visibility = chebyshev(sample_depth(v, k.index, k.depth), w.distance, o.variance_floor);
    w.trilinear = (off[0] ? alpha[0] : 1.f - alpha[0]) * (off[1] ? alpha[1] : 1.f - alpha[1]) *
                  (off[2] ? alpha[2] : 1.f - alpha[2]);
    w.weight = std::max(w.backface * w.visibility, o.min_weight) * w.trilinear;
    if (!(w.weight > 0.f)) continue;
    if (atlas) irradiance[count] = k.irradiance;
    out[count++] = w;
  }
  return count;
}

}  // namespace

Rgb DdgiVolume::atlas_irradiance(uint32_t probe, const Vec3& n) const {
  if (!irradiance_.data || probe >= desc_.probe_count) return {0.f, 0.f, 0.f};
  return tile_irradiance(*this, probe, tile_texels(*this, tile_cell(probe_coord(probe)), desc_.irradiance_tile, n));
}

uint32_t DdgiVolume::irradiance_texels(uint32_t probe, const Vec3& n, AtlasTexel out[4]) const {
  if (!irradiance_.data || probe >= desc_.probe_count) return 0;
  const TileTexels t = tile_texels(*this, tile_cell(probe_coord(probe)), desc_.irradiance_tile, n);
  for (int k = 0; k < 4; ++k) out[k] = AtlasTexel{t.x[k], t.y[k], t.w[k]};
  return 4;
}

Rgb DdgiVolume::sample_irradiance(const Vec3& p, const Vec3& n, const SampleOptions& o) const {
  Rgb e;
  try_sample_irradiance(p, n, e, o);
  return e;
}

uint32_t DdgiVolume::probe_weights(const Vec3& p, const Vec3& n, ProbeWeight out[8], const SampleOptions& o) const {
  return weigh_probes(*this, p, n, o, out, nullptr);
}

bool DdgiVolume::try_sample_irradiance(const Vec3& p, const Vec3& n, Rgb& out, const SampleOptions& o) const {
  float sight;
  return try_sample_irradiance(p, n, out, sight, o);
}

bool DdgiVolume::try_sample_irradiance(const Vec3& p, const Vec3& n, Rgb& out, float& sight,
                                       const SampleOptions& o) const {
  out = {0.f, 0.f, 0.f};
  sight = 0.f;
  ProbeWeight weights[8];
  TileTexels texels[8];
  const uint32_t count = weigh_probes(*this, p, n, o, weights, texels);
  for (uint32_t i = 0; i < count; ++i) sight = std::max(sight, weights[i].backface * weights[i].visibility);
  // The atlas's texels are irradiance already: weighted as they are. The SH are weighted, then
  // turned into irradiance once.
  const bool atlas = o.use_irradiance_atlas && irradiance_.data != nullptr;
  float sum[27] = {};
  float coefficients[27];
  float sum_weight = 0.f;
  for (uint32_t i = 0; i < count; ++i) {
    const float weight = weights[i].weight;
    if (atlas) {
      const Rgb e = tile_irradiance(*this, weights[i].probe, texels[i]);
      for (int k = 0; k < 3; ++k) sum[k] += e[k] * weight;
    } else {
      sh_probe(weights[i].probe, coefficients);
      for (uint32_t k = 0; k < desc_.sh_coefficients * 3; ++k) sum[k] += coefficients[k] * weight;
    }
    sum_weight += weight;
  }
  if (!(sum_weight > 0.f)) return false;
  if (atlas) {
    for (int k = 0; k < 3; ++k) {
      const float e = sum[k] / sum_weight;
      out[size_t(k)] = e > 0.f ? e : 0.f;  // also maps NaN to 0
    }
    return true;
  }
  for (uint32_t k = 0; k < desc_.sh_coefficients * 3; ++k) sum[k] /= sum_weight;
  out = loader::sh_irradiance(sum, desc_.sh_coefficients, n);
  return true;
}

}  // namespace gibake::loader
