// A hit's packed shading record (bake/scene/triangle_shading.h) holds the scene's own values for
// its triangle (index, material, corners' indices, uvs and normals; zeros where the scene has
// none), and a traced hit carries the record of the triangle it hit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "bake/scene/material.h"
#include "bake/scene/prepare.h"
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

// Every triangle's record against the scene's arrays, read here by index.
void expect_records_hold_the_scene(const Scene& s) {
  const bool uvs = !s.uvs.empty(), normals = !s.normals.empty();
  for (uint32_t t = 0; t < s.triangle_count(); ++t) {
    const TriangleShading r = triangle_shading(s, t);
    EXPECT_EQ(r.triangle, t);
    EXPECT_EQ(r.material, s.tri_material[t]);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = s.indices[size_t(t) * 3 + size_t(k)];
      EXPECT_EQ(r.vertex[k], v) << "triangle " << t;
      for (int j = 0; j < 2; ++j)
        EXPECT_TRUE(same_bits(r.uv[k * 2 + j], uvs ? s.uvs[size_t(v) * 2 + size_t(j)] : 0.f)) << "triangle " << t;
      for (int j = 0; j < 3; ++j)
        EXPECT_TRUE(same_bits(r.normal[k * 3 + j], normals ? s.normals[size_t(v) * 3 + size_t(j)] : 0.f))
            << "triangle " << t;
    }
    EXPECT_EQ(&triangle_material(s, r), t % 4 == 3 ? &triangle_material(s, t) : &s.materials[size_t(r.material)]);
  }
}

}  // namespace

TEST(TriangleShading, ARecordHoldsItsTrianglesValues) { expect_records_hold_the_scene(mixed_sphere()); }

TEST(TriangleShading, RecordsWithoutNormalsUvsOrColours) {
  Scene s = mixed_sphere();
  s.normals.clear();
  s.uvs.clear();
  s.colors.clear();
  expect_records_hold_the_scene(s);
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
    const TriangleShading own = triangle_shading(s, hit.triangle);
    EXPECT_EQ(std::memcmp(hit.shading, &own, sizeof(own)), 0) << "triangle " << hit.triangle;
  }
  EXPECT_GT(hits, 32);
}
