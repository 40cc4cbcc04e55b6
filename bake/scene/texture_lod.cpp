#include "bake/scene/texture_lod.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

namespace gibake {

namespace {

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
float linear_to_srgb(float c) { return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f; }

// sRGB byte -> linear, and linear (12-bit) -> sRGB byte, built once per TextureLod.
struct SrgbTables {
  std::array<float, 256> decode{};
  std::array<uint8_t, 4096> encode{};
  SrgbTables() {
    for (int i = 0; i < 256; ++i) decode[size_t(i)] = srgb_to_linear(i / 255.f);
    for (int i = 0; i < 4096; ++i)
      encode[size_t(i)] = static_cast<uint8_t>(std::lround(255.f * linear_to_srgb((i + 0.5f) / 4096.f)));
  }
};

// One output texel from four source texels: colour averaged as linear light (sums in the same order
// as the general loop below, so the bytes are the same), alpha rounded as lround(sum / 4).
// `coverage` (the texture's alpha is a mask or a blend: texture_is_coverage): colour weighted by
// alpha, so that a level holds the colour of the texels a ray can hit (the alpha test runs on the
// full-resolution image) and not the fill of the cut-out ones; a level's alpha is its texels' mean,
// so weighing level by level gives the alpha-weighted mean over all the texels it covers. Four
// cut-out texels average plainly.
inline void average4(const uint8_t* a, const uint8_t* b, const uint8_t* c, const uint8_t* d, const SrgbTables& t,
                     bool coverage, uint8_t* o) {
  const float wsum = coverage ? float(unsigned(a[3]) + b[3] + c[3] + d[3]) : 0.f;
  for (int k = 0; k < 3; ++k) {
    float mean;
    if (wsum > 0.f)
      mean = (((t.decode[a[k]] * a[3] + t.decode[b[k]] * b[3]) + t.decode[c[k]] * c[3]) + t.decode[d[k]] * d[3]) / wsum;
    else
      mean = (((t.decode[a[k]] + t.decode[b[k]]) + t.decode[c[k]]) + t.decode[d[k]]) / 4.f;
    o[k] = t.encode[size_t(std::min(4095.f, mean * 4096.f))];
  }
  o[3] = static_cast<uint8_t>((unsigned(a[3]) + b[3] + c[3] + d[3] + 2) >> 2);
}

constexpr size_t kParallelTexels = size_t(1) << 16;

MipLevel downsample(const uint8_t* src, int w, int h, const SrgbTables& t, bool coverage) {
  MipLevel m;
  m.width = std::max(1, w / 2);
  m.height = std::max(1, h / 2);
  m.rgba8.resize(size_t(m.width) * m.height * 4);
  if (w % 2 == 0 && h % 2 == 0) {  // the usual power-of-two texture: no edge clamping
    auto rows = [&](size_t y0, size_t y1) {
      for (size_t y = y0; y < y1; ++y) {
        const uint8_t* r0 = &src[2 * y * size_t(w) * 4];
        const uint8_t* r1 = r0 + size_t(w) * 4;
        uint8_t* o = &m.rgba8[y * size_t(m.width) * 4];
        for (int x = 0; x < m.width; ++x, r0 += 8, r1 += 8, o += 4) average4(r0, r0 + 4, r1, r1 + 4, t, coverage, o);
      }
    };
    // A large level's rows in parallel too: one big texture's chain would otherwise hold the
    // set-up back on a many-core machine (each output texel is independent: same bytes).
    if (size_t(m.width) * m.height >= kParallelTexels)
      tbb::parallel_for(tbb::blocked_range<size_t>(0, size_t(m.height), 32),
                        [&](const tbb::blocked_range<size_t>& r) { rows(r.begin(), r.end()); });
    else
      rows(0, size_t(m.height));
    return m;
  }
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      float sum[4] = {0, 0, 0, 0}, weighted[3] = {0, 0, 0};
      int n = 0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const int sx = std::min(w - 1, 2 * x + dx), sy = std::min(h - 1, 2 * y + dy);
          const uint8_t* p = &src[(size_t(sy) * w + sx) * 4];
          for (int c = 0; c < 3; ++c) {
            sum[c] += t.decode[p[c]];
            weighted[c] += t.decode[p[c]] * p[3];
          }
          sum[3] += p[3];
          ++n;
        }
      uint8_t* o = &m.rgba8[(size_t(y) * m.width + x) * 4];
      const bool by_alpha = coverage && sum[3] > 0.f;  // as average4
      for (int c = 0; c < 3; ++c) {
        const float mean = by_alpha ? weighted[c] / sum[3] : sum[c] / float(n);
        o[c] = t.encode[size_t(std::min(4095.f, mean * 4096.f))];
      }
      o[3] = static_cast<uint8_t>(std::lround(sum[3] / float(n)));
    }
  return m;
}

std::vector<MipLevel> build_chain(const Texture& tex, const SrgbTables& t, bool coverage) {
  std::vector<MipLevel> chain;
  if (tex.width <= 0 || tex.height <= 0 || tex.rgba8.size() < size_t(tex.width) * tex.height * 4) return chain;
  const uint8_t* src = tex.rgba8.data();
  int w = tex.width, h = tex.height;
  while (w > 1 || h > 1) {
    chain.push_back(downsample(src, w, h, t, coverage));
    src = chain.back().rgba8.data();
    w = chain.back().width;
    h = chain.back().height;
  }
  return chain;
}

}  // namespace

bool texture_is_coverage(const Scene& scene, int texture) {
  for (const Material& m : scene.materials)
    if (m.alpha_mode != AlphaMode::Opaque && m.base_color_texture.texture == texture) return true;
  return false;
}

TextureLod::TextureLod(const Scene& scene, const Context& ctx, tbb::task_arena* shared) {
  const SrgbTables tables;
  mips_.resize(scene.textures.size());
  std::unique_ptr<tbb::task_arena> own;
  if (!shared)
    own = ctx.threads > 0 ? std::make_unique<tbb::task_arena>(int(ctx.threads)) : std::make_unique<tbb::task_arena>();
  tbb::task_arena* arena = shared ? shared : own.get();
  const size_t tris = scene.triangle_count();
  extent_.assign(tris, UvExtent{});
  std::vector<char> coverage(scene.textures.size());
  for (size_t i = 0; i < coverage.size(); ++i) coverage[i] = texture_is_coverage(scene, int(i));
  arena->execute([&] {
    tbb::parallel_for(
        size_t(0), mips_.size(), [&](size_t i) { mips_[i] = build_chain(scene.textures[i], tables, coverage[i] != 0); },
        tbb::simple_partitioner());
    if (scene.uvs.size() < scene.vertex_count() * 2) return;
    tbb::parallel_for(size_t(0), tris, [&](size_t t) {
      const uint32_t* idx = &scene.indices[t * 3];
      const float* p0 = &scene.positions[size_t(idx[0]) * 3];
      const float* p1 = &scene.positions[size_t(idx[1]) * 3];
      const float* p2 = &scene.positions[size_t(idx[2]) * 3];
      const float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
      const float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
      const float cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
                  cz = e1[0] * e2[1] - e1[1] * e2[0];
      const float world = std::sqrt(cx * cx + cy * cy + cz * cz);
      const float* t0 = &scene.uvs[size_t(idx[0]) * 2];
      const float* t1 = &scene.uvs[size_t(idx[1]) * 2];
      const float* t2 = &scene.uvs[size_t(idx[2]) * 2];
      const float uv = std::fabs((t1[0] - t0[0]) * (t2[1] - t0[1]) - (t2[0] - t0[0]) * (t1[1] - t0[1]));
      const float r = world > 0.f ? std::sqrt(uv / world) : 0.f;
      extent_[t].uv_per_metre = std::isfinite(r) ? r : 0.f;
      const float cap = kMaxFootprintOfTriangle * std::sqrt(0.5f * uv);
      extent_[t].max_uv_width = std::isfinite(cap) ? cap : 0.f;
    });
  });
}

float TextureLod::level_of(uint32_t tri, float width, float cos_theta, int w, int h, float su, float sv) const {
  if (tri >= extent_.size() || !(width > 0.f)) return 0.f;
  const UvExtent& e = extent_[tri];
  const float uv_width = std::min(width / std::max(std::fabs(cos_theta), 0.1f) * e.uv_per_metre, e.max_uv_width);
  const float texels = uv_width * std::sqrt(float(w) * float(h) * std::fabs(su * sv));
  return texels > 1.f && std::isfinite(texels) ? std::log2(texels) : 0.f;
}

}  // namespace gibake
