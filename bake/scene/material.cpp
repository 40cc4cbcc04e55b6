#include "bake/scene/material.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace gibake {
using kernels::float3;

namespace {

const Material& default_material() {
  static const Material m{};
  return m;
}

const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const float c = i / 255.f;
      t[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }
    return t;
  }();
  return table;
}

int wrap_coord(int i, int n, int mode) {
  if (i >= 0 && i < n) return i;  // inside: every mode agrees (and no integer division)
  if (mode == 33071) return i < 0 ? 0 : (i >= n ? n - 1 : i);  // CLAMP_TO_EDGE
  if (mode == 33648) {                                         // MIRRORED_REPEAT
    const int period = 2 * n;
    int m = i % period;
    if (m < 0) m += period;
    return m < n ? m : period - 1 - m;
  }
  int m = i % n;  // REPEAT
  return m < 0 ? m + n : m;
}

// The four texels a bilinear read of one level takes at (u, v) (KHR_texture_transform applied),
// row by row, and their weights.
BilinearTaps bilinear_taps(int width, int height, int wrap_s, int wrap_t, const uint8_t* rgba8, const TextureRef& ref,
                           float u, float v) {
  if (ref.has_transform) {
    // KHR_texture_transform: uv' = T * R * S * uv.
    const float su = u * ref.scale[0], sv = v * ref.scale[1];
    const float c = std::cos(ref.rotation), s = std::sin(ref.rotation);
    u = c * su + s * sv + ref.offset[0];
    v = -s * su + c * sv + ref.offset[1];
  }
  const float x = u * width - 0.5f, y = v * height - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int xs[2] = {wrap_coord(x0, width, wrap_s), wrap_coord(x0 + 1, width, wrap_s)};
  const int ys[2] = {wrap_coord(y0, height, wrap_t), wrap_coord(y0 + 1, height, wrap_t)};
  const float wx[2] = {1.f - ax, ax}, wy[2] = {1.f - ay, ay};
  BilinearTaps taps;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      taps.texel[2 * j + i] = &rgba8[(size_t(ys[j]) * width + xs[i]) * 4];
      taps.weight[2 * j + i] = wx[i] * wy[j];
    }
  return taps;
}

std::array<float, 4> read_taps(const BilinearTaps& taps, bool srgb) {
  const auto& lut = srgb_table();
  std::array<float, 4> out{};
  for (int k = 0; k < 4; ++k) {
    const uint8_t* p = taps.texel[k];
    const float w = taps.weight[k];
    for (int c = 0; c < 3; ++c) out[c] += w * (srgb ? lut[p[c]] : p[c] / 255.f);
    out[3] += w * (p[3] / 255.f);
  }
  return out;
}

// A hint: the texels' cache lines are asked for now, read later (no value depends on it).
void prefetch_taps(const BilinearTaps& taps) {
#if defined(__GNUC__) || defined(__clang__)
  for (const uint8_t* p : taps.texel) __builtin_prefetch(p);
#else
  (void)taps;
#endif
}

// The taps of the mip level the footprint asks for (level 0 without one); false for a texture
// without pixels, which reads as white.
bool texture_taps(const Scene& scene, const TextureRef& ref, float u, float v, uint32_t tri, const TextureFootprint* fp,
                  BilinearTaps& out) {
  const Texture& full = scene.textures[ref.texture];
  if (full.width <= 0 || full.height <= 0 || full.rgba8.size() < size_t(full.width) * full.height * 4) return false;
  if (fp && fp->lod && !fp->lod->empty()) {
    const std::vector<MipLevel>& chain = fp->lod->levels(ref.texture);
    const float level = fp->lod->level_of(tri, fp->width, fp->cos_theta, full.width, full.height,
                                          ref.has_transform ? ref.scale[0] : 1.f, ref.has_transform ? ref.scale[1] : 1.f);
    const int k = std::min(static_cast<int>(level + 0.5f), static_cast<int>(chain.size()));
    if (k > 0) {
      const MipLevel& m = chain[size_t(k - 1)];
      out = bilinear_taps(m.width, m.height, full.wrap_s, full.wrap_t, m.rgba8.data(), ref, u, v);
      return true;
    }
  }
  out = bilinear_taps(full.width, full.height, full.wrap_s, full.wrap_t, full.rgba8.data(), ref, u, v);
  return true;
}

// Bilinear RGBA sample of the mip level the footprint asks for (level 0 without one); rgb decoded
// from sRGB when srgb is set, alpha always linear.
std::array<float, 4> sample_texture(const Scene& scene, const TextureRef& ref, float u, float v, bool srgb,
                                    uint32_t tri = 0, const TextureFootprint* fp = nullptr) {
  BilinearTaps taps;
  if (!texture_taps(scene, ref, u, v, tri, fp, taps)) return {1.f, 1.f, 1.f, 1.f};
  return read_taps(taps, srgb);
}

bool has_texture(const Scene& scene, const TextureRef& ref) {
  return ref.texture >= 0 && static_cast<size_t>(ref.texture) < scene.textures.size();
}

bool has_uvs(const Scene& scene) { return scene.uvs.size() >= scene.vertex_count() * 2; }
bool has_normals(const Scene& scene) { return scene.normals.size() >= scene.vertex_count() * 3; }

// A hit's corners: vertex indices, barycentric weights, and its record's corner uvs and normals
// (nullptr where the scene has none).
struct Corners {
  uint32_t i0, i1, i2;
  float w0, w1, w2;
  const float* uv[3];
  const float* normal[3];
};
Corners corners(const Scene& scene, const TriangleShading& tri, float u, float v) {
  Corners c{tri.vertex[0], tri.vertex[1], tri.vertex[2], 1.f - u - v, u, v, {}, {}};
  const bool uvs = has_uvs(scene), normals = has_normals(scene);
  for (int k = 0; k < 3; ++k) {
    c.uv[k] = uvs ? &tri.uv[k * 2] : nullptr;
    c.normal[k] = normals ? &tri.normal[k * 3] : nullptr;
  }
  return c;
}

void interp_uv(const Corners& c, float& s, float& t) {
  s = t = 0.f;
  if (!c.uv[0]) return;
  s = c.w0 * c.uv[0][0] + c.w1 * c.uv[1][0] + c.w2 * c.uv[2][0];
  t = c.w0 * c.uv[0][1] + c.w1 * c.uv[1][1] + c.w2 * c.uv[2][1];
}

std::array<float, 4> vertex_color(const Scene& scene, const Corners& c) {
  if (scene.colors.size() < scene.vertex_count() * 4) return {1.f, 1.f, 1.f, 1.f};
  std::array<float, 4> out{};
  for (int k = 0; k < 4; ++k)
    out[k] = c.w0 * scene.colors[c.i0 * 4 + k] + c.w1 * scene.colors[c.i1 * 4 + k] + c.w2 * scene.colors[c.i2 * 4 + k];
  return out;
}

const Material& material_at(const Scene& scene, int32_t m) {
  if (m < 0 || static_cast<size_t>(m) >= scene.materials.size()) return default_material();
  return scene.materials[m];
}

int32_t material_index(const Scene& scene, uint32_t tri) {
  return tri < scene.tri_material.size() ? scene.tri_material[tri] : -1;
}

float alpha_at(const Scene& scene, const Material& m, const Corners& c) {
  float a = m.base_color[3] * vertex_color(scene, c)[3];
  if (has_texture(scene, m.base_color_texture)) {
    float s, t;
    interp_uv(c, s, t);
    a *= sample_texture(scene, m.base_color_texture, s, t, false)[3];
  }
  return a;
}

// All of the surface sample but the base colour's texels, whose loads start here.
PendingSurface begin_at(const Scene& scene, const Material& m, uint32_t tri, const Corners& c,
                        const TextureFootprint& fp) {
  PendingSurface pending;
  SurfaceSample& s = pending.sample;
  s.double_sided = m.double_sided;
  float tu = 0.f, tv = 0.f;
  const bool transmission_map = m.transmission > 0.f && has_texture(scene, m.transmission_texture);
  const bool need_uv = has_texture(scene, m.base_color_texture) || has_texture(scene, m.emissive_texture) ||
                       transmission_map;
  if (need_uv) interp_uv(c, tu, tv);
  const std::array<float, 4> vc = vertex_color(scene, c);
  s.albedo = {m.base_color[0] * vc[0], m.base_color[1] * vc[1], m.base_color[2] * vc[2]};
  if (has_texture(scene, m.base_color_texture)) {
    pending.textured = texture_taps(scene, m.base_color_texture, tu, tv, tri, &fp, pending.base_color);
    if (pending.textured) prefetch_taps(pending.base_color);
  }
  s.transmission = m.transmission;
  if (transmission_map) s.transmission *= sample_texture(scene, m.transmission_texture, tu, tv, false, tri, &fp)[0];
  if (m.is_emissive()) {
    std::array<float, 4> e{m.emissive[0], m.emissive[1], m.emissive[2], 1.f};
    if (has_texture(scene, m.emissive_texture)) {
      const auto t = sample_texture(scene, m.emissive_texture, tu, tv, true, tri, &fp);
      for (int k = 0; k < 3; ++k) e[k] *= t[k];
    }
    s.emission = float3{e[0], e[1], e[2]} * m.emissive_strength;
  }
  if (c.normal[0]) {
    float3 n =
        kernels::load3(c.normal[0]) * c.w0 + kernels::load3(c.normal[1]) * c.w1 + kernels::load3(c.normal[2]) * c.w2;
    s.normal = kernels::normalize(n);
  }
  return pending;
}

}  // namespace

const Material& triangle_material(const Scene& scene, uint32_t tri) {
  return material_at(scene, material_index(scene, tri));
}

const Material& triangle_material(const Scene& scene, const TriangleShading& tri) {
  return material_at(scene, tri.material);
}

float alpha_cutoff_of(const Material& m, float blend_cutoff) {
  if (m.alpha_mode == AlphaMode::Mask) return m.alpha_cutoff;
  if (m.alpha_mode == AlphaMode::Blend) return blend_cutoff > 0.f ? blend_cutoff : -1.f;
  return -1.f;
}

float surface_alpha(const Scene& scene, uint32_t tri, float u, float v) {
  return surface_alpha(scene, triangle_shading(scene, tri), u, v);
}

float surface_alpha(const Scene& scene, const TriangleShading& tri, float u, float v) {
  return alpha_at(scene, triangle_material(scene, tri), corners(scene, tri, u, v));
}

SurfaceSample surface_sample(const Scene& scene, uint32_t tri, float u, float v) {
  return surface_sample(scene, tri, u, v, TextureFootprint{});
}

SurfaceSample surface_sample(const Scene& scene, uint32_t tri, float u, float v, const TextureFootprint& fp) {
  return surface_sample(scene, triangle_shading(scene, tri), u, v, fp);
}

SurfaceSample surface_sample(const Scene& scene, const TriangleShading& tri, float u, float v,
                             const TextureFootprint& fp) {
  return finish_surface_sample(begin_surface_sample(scene, tri, u, v, fp));
}

PendingSurface begin_surface_sample(const Scene& scene, const TriangleShading& tri, float u, float v,
                                    const TextureFootprint& fp) {
  return begin_at(scene, triangle_material(scene, tri), tri.triangle, corners(scene, tri, u, v), fp);
}

SurfaceSample finish_surface_sample(const PendingSurface& pending) {
  SurfaceSample s = pending.sample;
  if (pending.textured) {
    const std::array<float, 4> t = read_taps(pending.base_color, true);
    s.albedo = {s.albedo.x * t[0], s.albedo.y * t[1], s.albedo.z * t[2]};
  }
  return s;
}

TriangleShading triangle_shading(const Scene& scene, uint32_t tri) {
  TriangleShading r;
  r.triangle = tri;
  r.material = material_index(scene, tri);
  const bool uvs = has_uvs(scene), normals = has_normals(scene);
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = scene.indices[size_t(tri) * 3 + k];
    r.vertex[k] = v;
    if (uvs) std::copy_n(&scene.uvs[size_t(v) * 2], 2, &r.uv[k * 2]);
    if (normals) std::copy_n(&scene.normals[size_t(v) * 3], 3, &r.normal[k * 3]);
  }
  return r;
}

}  // namespace gibake
