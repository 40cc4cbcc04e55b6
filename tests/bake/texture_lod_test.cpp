// Texture level of detail: mip levels average linear light, and the level a footprint picks
// follows the texel density (independent answers: sRGB arithmetic and log2 of a known ratio).
#include <gtest/gtest.h>

#include <cmath>

#include "bake/scene/material.h"
#include "bake/scene/texture_lod.h"
#include "tests/bake/scene_builders.h"

using namespace gibake;

namespace {
float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// A 1 m x 1 m quad with uv 0..1 and a w x h checker of black and white sRGB texels.
Scene checker_quad(int w, int h) {
  Scene s;
  const int m = test::add_material(s, 1.f);
  test::add_quad(s, {0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}, {0, 1, 0}, m);
  for (size_t v = 0; v < s.vertex_count(); ++v) {  // uv = (x, z): 1 uv unit per metre
    s.uvs[v * 2] = s.positions[v * 3];
    s.uvs[v * 2 + 1] = s.positions[v * 3 + 2];
  }
  Texture t;
  t.width = w;
  t.height = h;
  t.rgba8.resize(size_t(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t c = (x + y) % 2 ? 255 : 0;
      uint8_t* px = &t.rgba8[(size_t(y) * w + x) * 4];
      px[0] = px[1] = px[2] = c;
      px[3] = 255;
    }
  s.textures.push_back(t);
  s.materials[size_t(m)].base_color_texture.texture = 0;
  return s;
}

// The same quad mapped to u 0.125..0.375 of a 64 x 64 atlas whose left half is white and right
// half black: an island of white, away from the wrap, in a texture that is half black overall.
Scene atlas_island_quad() {
  Scene s = checker_quad(64, 64);
  for (size_t v = 0; v < s.vertex_count(); ++v) s.uvs[v * 2] = 0.125f + 0.25f * s.uvs[v * 2];
  Texture& t = s.textures[0];
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      uint8_t* px = &t.rgba8[(size_t(y) * 64 + x) * 4];
      px[0] = px[1] = px[2] = x < 32 ? 255 : 0;
    }
  return s;
}
}  // namespace

TEST(TextureLod, MipsAverageLinearLight) {
  const Scene s = checker_quad(64, 64);
  const TextureLod lod(s, Context{});
  const std::vector<MipLevel>& chain = lod.levels(0);
  ASSERT_EQ(chain.size(), 6u);  // 32, 16, 8, 4, 2, 1
  EXPECT_EQ(chain.back().width, 1);
  // Half black, half white in linear light is 0.5 linear = sRGB byte 188, not 128.
  const int byte = chain[0].rgba8[0];
  EXPECT_NEAR(srgb_to_linear(byte / 255.f), 0.5f, 0.01f);
  EXPECT_EQ(chain.back().rgba8[0], byte);
}

// A cut-out texture (opaque red texels in a checker with transparent white ones): under a MASK or
// BLEND material its levels keep the red a ray can hit (the alpha test cuts the rest away at full
// resolution), not red and white mixed; under an opaque material, whose alpha means nothing, they
// mix. Alpha itself averages either way.
TEST(TextureLod, CutOutTexelsLeaveNoColourInTheLevels) {
  Scene s = checker_quad(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      uint8_t* px = &s.textures[0].rgba8[(size_t(y) * 64 + x) * 4];
      const bool opaque = (x + y) % 2 == 0;
      px[0] = 255;
      px[1] = px[2] = opaque ? 0 : 255;
      px[3] = opaque ? 255 : 0;
    }
  for (AlphaMode mode : {AlphaMode::Mask, AlphaMode::Blend, AlphaMode::Opaque}) {
    s.materials[0].alpha_mode = mode;
    EXPECT_EQ(texture_is_coverage(s, 0), mode != AlphaMode::Opaque);
    const TextureLod lod(s, Context{});
    for (const MipLevel& level : lod.levels(0)) {
      const uint8_t* px = &level.rgba8[0];
      EXPECT_EQ(px[0], 255);
      EXPECT_NEAR(px[3], 128, 1);  // half of the texels are opaque
      if (mode == AlphaMode::Opaque)
        EXPECT_NEAR(srgb_to_linear(px[1] / 255.f), 0.5f, 0.01f) << level.width;  // white and red, mixed
      else
        EXPECT_EQ(px[1], 0) << level.width;  // red alone
    }
  }
  // A level whose texels are all cut out keeps their plain colour.
  for (size_t i = 0; i < s.textures[0].rgba8.size(); i += 4) s.textures[0].rgba8[i + 3] = 0;
  s.materials[0].alpha_mode = AlphaMode::Mask;
  const TextureLod clear(s, Context{});
  EXPECT_NEAR(srgb_to_linear(clear.levels(0).back().rgba8[1] / 255.f), 0.5f, 0.01f);
}

TEST(TextureLod, FootprintPicksTheLevelOfItsTexelCount) {
  const Scene s = checker_quad(64, 64);
  const TextureLod lod(s, Context{});
  // 64 texels per metre: a 1/64 m footprint covers one texel (level 0), 1/8 m covers 8 (level 3).
  EXPECT_NEAR(lod.level_of(0, 1.f / 64, 1.f, 64, 64, 1.f, 1.f), 0.f, 1e-4f);
  EXPECT_NEAR(lod.level_of(0, 1.f / 8, 1.f, 64, 64, 1.f, 1.f), 3.f, 1e-4f);
  EXPECT_NEAR(lod.level_of(0, 1.f / 16, 0.5f, 64, 64, 1.f, 1.f), 3.f, 1e-4f);  // grazing: twice as long
  // Never wider than a quarter of the triangle's extent: sqrt(0.5) x 64 / 4 texels.
  EXPECT_NEAR(lod.level_of(0, 1.f / 8, 0.5f, 64, 64, 1.f, 1.f), std::log2(std::sqrt(0.5f) * 16.f), 1e-4f);
  // A wide footprint reads the average (0.5 linear) everywhere; without one the checker shows.
  float sharp_spread = 0.f;
  for (int i = 0; i < 16; ++i) {
    const float u = 0.05f + 0.04f * float(i), v = 0.03f + 0.02f * float(i % 5);
    EXPECT_NEAR(surface_sample(s, 0, u, v, TextureFootprint{&lod, 2.f, 1.f}).albedo.x, 0.5f, 0.01f);
    sharp_spread = std::max(sharp_spread, std::fabs(surface_sample(s, 0, u, v).albedo.x - 0.5f));
  }
  EXPECT_GT(sharp_spread, 0.2f);
}

// A cone far wider than its triangle reads the triangle's own texels, not the atlas around them:
// the island is white, so every footprint reads albedo 1 (the uncapped coarsest level is the
// texture's mean, 0.5).
TEST(TextureLod, AWideFootprintStaysOnItsTrianglesIsland) {
  const Scene s = atlas_island_quad();
  const TextureLod lod(s, Context{});
  // The quad's two triangles each cover half of a 16 x 64 texel strip: about 22 texels across.
  const float cap = lod.level_of(0, 1000.f, 1.f, 64, 64, 1.f, 1.f);
  EXPECT_NEAR(cap, std::log2(kMaxFootprintOfTriangle * std::sqrt(0.5f * 16.f * 64.f)), 1e-3f);
  EXPECT_LT(lod.level_of(0, 0.01f, 1.f, 64, 64, 1.f, 1.f), cap);  // a narrow footprint is not capped
  for (float width : {0.05f, 0.5f, 5.f, 500.f})
    for (int i = 0; i < 8; ++i) {
      const float u = 0.1f + 0.1f * float(i), v = 0.05f + 0.05f * float(i);
      EXPECT_NEAR(surface_sample(s, 0, u * 0.5f, v * 0.5f, TextureFootprint{&lod, width, 0.2f}).albedo.x, 1.f, 0.02f)
          << "footprint " << width << " m at (" << u << ", " << v << ")";
    }
}
