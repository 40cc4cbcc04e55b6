// A hit's packed shading record (bake/scene/triangle_shading.h) must give what the scene's own
// arrays give, to the bit: colour, emission, transmission, normal and alpha, with and without
// texture footprints, for every triangle and material kind, and for scenes without normals or uvs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "bake/scene/material.h"
#include "bake/scene/prepare.h"
#include "bake/scene/texture_lod.h"
#include "tests/bake/scene_builders.h"

using namespace gibake;

namespace {

// A sphere whose triangles take turns among four materials: textured opaque, textured MASK with an
// emissive texture, glass with a transmission map, and none (-1, the default material); uvs from
// the position, vertex colours, and an 8 x 8 texture of varied RGBA.
Scene mixed_sphere() {
  Scene s;
  const int opaque = test::add_material(s, 0.8f);
  const int masked = test::add_material(s, 0.6f, 2.f, true);
  const int glass = test::add_material(s, 0.9f);
  test::add_sphere(s, {0.f, 0.f, 0.f}, 1.f, 12, 8, opaque);
  Texture t;
  t.width = t.height = 8;
  t.wrap_t = 33648;  // MIRRORED_REPEAT
  for (int i = 0; i < 8 * 8 * 4; ++i) t.rgba8.push_back(uint8_t((i * 37 + 11) % 256));
  s.textures.push_back(t);
  Material& m = s.materials[size_t(masked)];
  m.alpha_mode = AlphaMode::Mask;
  m.base_color_texture.texture = 0;
  m.emissive_texture.texture = 0;
  s.materials[size_t(opaque)].base_color_texture.texture = 0;
  s.materials[size_t(glass)].transmission = 0.7f;
  s.materials[size_t(glass)].transmission_texture.texture = 0;
  for (size_t v = 0; v < s.vertex_count(); ++v) {
    s.uvs[v * 2] = 1.7f * s.positions[v * 3] + 0.3f;
    s.uvs[v * 2 + 1] = -2.3f * s.positions[v * 3 + 2];
    for (int k = 0; k < 4; ++k) s.colors.push_back(0.5f + 0.5f * std::sin(float(v * 4 + k)));
  }
  const int kinds[4] = {opaque, masked, glass, -1};
  for (size_t t2 = 0; t2 < s.tri_material.size(); ++t2) s.tri_material[t2] = kinds[t2 % 4];
  return s;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

void expect_same(const SurfaceSample& a, const SurfaceSample& b, uint32_t tri) {
  const float fa[10] = {a.albedo.x,   a.albedo.y, a.albedo.z, a.emission.x, a.emission.y,
                        a.emission.z, a.normal.x, a.normal.y, a.normal.z,   a.transmission};
  const float fb[10] = {b.albedo.x,   b.albedo.y, b.albedo.z, b.emission.x, b.emission.y,
                        b.emission.z, b.normal.x, b.normal.y, b.normal.z,   b.transmission};
  for (int k = 0; k < 10; ++k) EXPECT_TRUE(same_bits(fa[k], fb[k])) << "triangle " << tri << " value " << k;
  EXPECT_EQ(a.double_sided, b.double_sided) << "triangle " << tri;
}

void expect_records_match(const Scene& s) {
  const TextureLod lod(s, Context{});
  const float bary[4][2] = {{0.2f, 0.3f}, {0.f, 0.f}, {0.9f, 0.05f}, {0.33f, 0.66f}};
  int textured = 0;
  for (uint32_t t = 0; t < s.triangle_count(); ++t) {
    const TriangleShading rec = triangle_shading(s, t);
    ASSERT_EQ(rec.triangle, t);
    EXPECT_EQ(&triangle_material(s, rec), &triangle_material(s, t));
    for (const auto& b : bary)
      for (const float width : {0.f, 0.05f, 3.f}) {
        const TextureFootprint fp{&lod, width, 0.6f};
        expect_same(surface_sample(s, t, b[0], b[1], fp), surface_sample(s, rec, b[0], b[1], fp), t);
        EXPECT_TRUE(same_bits(surface_alpha(s, t, b[0], b[1]), surface_alpha(s, rec, b[0], b[1])));
      }
    textured += triangle_material(s, t).base_color_texture.texture >= 0;
  }
  EXPECT_GT(textured, 0);
}

}  // namespace

TEST(TriangleShading, RecordsGiveTheScenesOwnSamples) { expect_records_match(mixed_sphere()); }

TEST(TriangleShading, RecordsWithoutNormalsUvsOrColours) {
  Scene s = mixed_sphere();
  s.normals.clear();
  s.uvs.clear();
  s.colors.clear();
  expect_records_match(s);
}

TEST(TriangleShading, AHitCarriesItsTrianglesRecord) {
  const Scene s = mixed_sphere();
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(s, Context{}, prepared).ok());
  int hits = 0;
  for (int i = 0; i < 64; ++i) {
    const float a = 0.1f * i, z = std::cos(0.37f * i) * 0.8f;
    const kernels::float3 org{3.f * std::cos(a), z, 3.f * std::sin(a)};
    const kernels::float3 dir = kernels::normalize(kernels::float3{0.1f * std::sin(float(i)), 0.f, 0.f} - org);
    const TraceHit hit = prepared->intersect(org, dir, 0.f, 10.f);
    if (hit.t < 0.f) continue;
    ++hits;
    ASSERT_NE(hit.shading, nullptr);
    EXPECT_EQ(hit.shading->triangle, hit.triangle);
    EXPECT_EQ(&hit_material(s, hit), &triangle_material(s, hit.triangle));
    const TextureFootprint fp{};
    expect_same(hit_surface(s, hit, fp), surface_sample(s, hit.triangle, hit.u, hit.v, fp), hit.triangle);
  }
  EXPECT_GT(hits, 32);
}
