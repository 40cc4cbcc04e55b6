// The shared-exponent irradiance atlas (GIBAKE_FORMAT_RGB9E5, format 1.5): the codec against values
// known in closed form and its error bound, and the writer's choice (--atlas-format rgb9e5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "io/bakefile/bake_file.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;
using loader::float_to_rgb9e5;
using loader::rgb9e5_to_float;

TEST(Rgb9e5, KnownValues) {
  // 1 = 256 * 2^-8: mantissa 256, exponent 16 (2^(16 - 24) = 2^-8).
  EXPECT_EQ(float_to_rgb9e5(1.f, 1.f, 1.f), (16u << 27) | (256u << 18) | (256u << 9) | 256u);
  EXPECT_EQ(rgb9e5_to_float(float_to_rgb9e5(1.f, 0.5f, 0.25f)), (std::array<float, 3>{1.f, 0.5f, 0.25f}));
  // The largest value, and beyond it, NaN and negatives clamped.
  EXPECT_EQ(rgb9e5_to_float(float_to_rgb9e5(65408.f, 1e9f, 0.f)), (std::array<float, 3>{65408.f, 65408.f, 0.f}));
  EXPECT_EQ(rgb9e5_to_float(float_to_rgb9e5(NAN, -3.f, 0.f)), (std::array<float, 3>{0.f, 0.f, 0.f}));
  // 511.75 rounds its mantissa up to 512: the exponent moves on (512 = 256 * 2^1).
  EXPECT_EQ(rgb9e5_to_float(float_to_rgb9e5(511.75f, 0.f, 0.f))[0], 512.f);
  // Below the smallest step (2^-24) a channel rounds to zero; a bright channel sets the step for all.
  EXPECT_EQ(rgb9e5_to_float(float_to_rgb9e5(1e-9f, 0.f, 0.f))[0], 0.f);
  EXPECT_EQ(rgb9e5_to_float(float_to_rgb9e5(1000.f, 0.9f, 1.f))[1], 0.f);  // step 2 at 1000: 0.9 rounds down
}

// Each channel within half a step of the shared exponent, at most 2^-9 of the largest channel.
TEST(Rgb9e5, ErrorBound) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  float worst = 0.f;
  for (int i = 0; i < 200000; ++i) {
    const float scale = std::exp2(-20.f + 36.f * u(rng));
    const float c[3] = {scale * u(rng), scale * u(rng), scale * u(rng)};
    if (std::max({c[0], c[1], c[2]}) > loader::kRgb9e5Max) continue;
    const std::array<float, 3> d = rgb9e5_to_float(float_to_rgb9e5(c[0], c[1], c[2]));
    const float largest = std::max({c[0], c[1], c[2]});
    for (int k = 0; k < 3; ++k) {
      const float error = std::fabs(d[k] - c[k]);
      ASSERT_LE(error, largest * std::exp2(-9.f) + std::exp2(-25.f)) << c[0] << " " << c[1] << " " << c[2];
      if (largest > std::exp2(-14.f)) worst = std::max(worst, error / largest);  // above the floor step
    }
  }
  std::printf("largest error relative to the largest channel (above 2^-14): %.3g (bound 2^-9 = %.3g)\n", worst,
              std::exp2(-9.0));
}

std::vector<uint8_t> build(const DdgiResult& r, FloatPrecision atlas) { return test::one_volume_file(r, atlas); }

TEST(Rgb9e5, TheWriterStoresTheIrradianceAtlasSoWhenItFits) {
  const DdgiResult r = test::make_ddgi(4, 3, 2, 2, 21);
  const std::vector<uint8_t> full = build(r, FloatPrecision::Full), shared = build(r, FloatPrecision::SharedExponent);
  loader::BakeFile a, b;
  ASSERT_FALSE(a.open_borrowed(full.data(), full.size()));
  const loader::Error e = b.open_borrowed(shared.data(), shared.size());
  ASSERT_FALSE(e) << e.message;
  EXPECT_EQ(b.header().version_minor, 5u);
  const loader::DdgiVolume &va = a.ddgi_volumes()[0], &vb = b.ddgi_volumes()[0];
  EXPECT_EQ(b.sections()[size_t(vb.section_index(GIBAKE_SECTION_DDGI_IRRADIANCE))].format,
            uint32_t(GIBAKE_FORMAT_RGB9E5));
  EXPECT_EQ(b.sections()[size_t(vb.section_index(GIBAKE_SECTION_DDGI_DEPTH))].format, uint32_t(GIBAKE_FORMAT_RG16F));
  EXPECT_LT(shared.size(), full.size());
  for (uint32_t y = 0; y < va.desc().irradiance_height; ++y)
    for (uint32_t x = 0; x < va.desc().irradiance_width; ++x) {
      const std::array<float, 4> t = va.irradiance_texel(x, y), s = vb.irradiance_texel(x, y);
      const float largest = std::max({t[0], t[1], t[2]});
      for (int k = 0; k < 3; ++k) ASSERT_LE(std::fabs(s[k] - t[k]), largest * std::exp2(-9.f) + 1e-6f);
      EXPECT_EQ(s[3], 1.f);
    }
  // The probe-major copies decode the same texels.
  loader::BakeFile tiles;
  ASSERT_FALSE(tiles.open_borrowed(shared.data(), shared.size(), loader::LoadOptions{true, true}));
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-0.2f, 1.2f);
  for (int i = 0; i < 500; ++i) {
    const loader::Vec3 p{-1.f + 4.5f * u(rng), 2.f * u(rng), -2.f + 2.f * u(rng)}, n{0.f, 1.f, 0.f};
    EXPECT_EQ(vb.sample_irradiance(p, n), tiles.ddgi_volumes()[0].sample_irradiance(p, n));
  }
  EXPECT_EQ(vb.desc().irradiance_scale, 1.f);  // the synthetic texels stay below 65408
  // Sunlight past 65408 lux: the texels are stored halved (a power of two), read back in lux.
  DdgiResult bright = r;
  bright.irradiance_atlas[0] = 100000.f;
  const std::vector<uint8_t> scaled = build(bright, FloatPrecision::SharedExponent);
  loader::BakeFile c;
  ASSERT_FALSE(c.open_borrowed(scaled.data(), scaled.size()));
  EXPECT_EQ(c.ddgi_volumes()[0].desc().irradiance_scale, 2.f);
  EXPECT_NEAR(c.ddgi_volumes()[0].irradiance_texel(0, 0)[0], 100000.f, 100000.f * std::exp2(-9.f));
  EXPECT_EQ(c.ddgi_volumes()[0].glsl_volume().spacing[3], 2.f);
  // A negative value cannot be held: the atlas is stored as Auto would store it.
  DdgiResult negative = r;
  negative.irradiance_atlas[4] = -1.f;
  const std::vector<uint8_t> fallback = build(negative, FloatPrecision::SharedExponent);
  loader::BakeFile d;
  ASSERT_FALSE(d.open_borrowed(fallback.data(), fallback.size()));
  const int32_t irr = d.ddgi_volumes()[0].section_index(GIBAKE_SECTION_DDGI_IRRADIANCE);
  EXPECT_EQ(d.sections()[size_t(irr)].format, uint32_t(GIBAKE_FORMAT_RGBA16F));
  EXPECT_EQ(d.ddgi_volumes()[0].desc().irradiance_scale, 0.f);
  EXPECT_EQ(d.header().version_minor, 2u);
}

}  // namespace
