// CPU sampler: agrees with direct SH evaluation at probes, continuous between probes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "synthetic.h"

namespace {

using namespace gibake;

loader::BakeFile open_result(const DdgiResult& r, std::vector<uint8_t>& bytes) {
  BakeOutputs outputs;
  outputs.ddgi = &r;
  BakeFileOptions options;
  options.atlas = gibake::FloatPrecision::Full;
  EXPECT_TRUE(build_bake_file(outputs, options, bytes).is_ok());
  loader::BakeFile file;
  EXPECT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
  return file;
}

loader::Vec3 unit(float x, float y, float z) {
  const float l = std::sqrt(x * x + y * y + z * z);
  return {x / l, y / l, z / l};
}

// The sampler reading the SH, not the synthetic volumes' irradiance atlas (random texels).
loader::SampleOptions from_sh() {
  loader::SampleOptions o;
  o.use_irradiance_atlas = false;
  return o;
}

TEST(Sampler, AllProbesEqualGivesTheirIrradianceEverywhere) {
  DdgiResult r = test::make_ddgi(3, 2, 2, 2, 21);
  for (size_t i = 0; i < r.sh.size(); ++i) r.sh[i] = r.sh[i % 27];
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  for (const loader::Vec3& p : {loader::Vec3{-1.f, 0.f, -2.f}, loader::Vec3{0.3f, 0.7f, -1.1f},
                                loader::Vec3{2.f, 1.f, 0.f}, loader::Vec3{5.f, -3.f, 9.f}}) {
    for (const loader::Vec3& n : {unit(0, 1, 0), unit(1, -1, 0.5f), unit(-0.2f, 0.1f, -1)}) {
      const loader::Rgb s = v.sample_irradiance(p, n, from_sh()), e = v.sh_irradiance(0, n);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[k], e[k], 1e-4f * std::max(1.f, e[k]));
    }
  }
}

TEST(Sampler, AtAProbeOnlyThatProbeContributes) {
  DdgiResult r = test::make_ddgi(3, 2, 2, 2, 22);
  std::fill(r.offsets.begin(), r.offsets.end(), 0.f);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  for (uint32_t probe : {0u, 1u, 7u, 11u}) {
    if (v.state(probe) != GIBAKE_PROBE_ACTIVE) continue;
    const loader::Vec3 p = v.probe_position(probe);
    const loader::Vec3 n = unit(0.3f, 0.8f, -0.5f);
    const loader::Rgb s = v.sample_irradiance(p, n, from_sh()), e = v.sh_irradiance(probe, n);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[k], e[k], 1e-4f * std::max(1.f, e[k])) << "probe " << probe;
    // The same through the atlas (the default): that probe's tile read at n.
    const loader::Rgb a = v.sample_irradiance(p, n), t = v.atlas_irradiance(probe, n);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], t[k], 1e-4f * std::max(1.f, t[k])) << "probe " << probe;
    EXPECT_NE(a, s) << "probe " << probe;  // the atlas, not the SH
  }
}

TEST(Sampler, ContinuousAlongALine) {
  DdgiResult r = test::make_ddgi(3, 2, 2, 2, 23);
  for (size_t i = 0; i < r.depth_atlas.size(); i += 2) {  // occluders beyond every probe pair
    r.depth_atlas[i] = 50.f;
    r.depth_atlas[i + 1] = 2500.f;
  }
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  const loader::Vec3 a{-1.2f, -0.1f, -2.1f}, b{2.2f, 1.1f, 2.1f};
  const loader::Vec3 n = unit(0.2f, 1.f, 0.1f);
  const int steps = 4000;
  loader::Rgb prev = v.sample_irradiance(a, n);
  float peak = 0.f, worst = 0.f;
  for (int i = 1; i <= steps; ++i) {
    const float t = float(i) / steps;
    const loader::Vec3 p{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
    const loader::Rgb s = v.sample_irradiance(p, n);
    for (int k = 0; k < 3; ++k) {
      peak = std::max(peak, s[k]);
      worst = std::max(worst, std::fabs(s[k] - prev[k]));
    }
    prev = s;
  }
  EXPECT_GT(peak, 0.f);
  EXPECT_LT(worst, 0.01f * peak) << "jump " << worst << " of peak " << peak;
}

TEST(Sampler, VisibilityDownweightsOccludedProbes) {
  DdgiResult r = test::make_ddgi(2, 1, 1, 1, 24);
  std::fill(r.offsets.begin(), r.offsets.end(), 0.f);
  std::fill(r.states.begin(), r.states.end(), ProbeState::Active);
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) {
      r.sh[c * 3 + k] = c == 0 ? 1.f : 0.f;        // probe 0: dim
      r.sh[12 + c * 3 + k] = c == 0 ? 100.f : 0.f;  // probe 1: bright, but occluded at 0.1 m
    }
  const int side = kDepthTexels + 2;
  for (int y = 0; y < r.depth_height; ++y)
    for (int x = 0; x < r.depth_width; ++x) {
      const float mean = x >= side ? 0.1f : 50.f;
      r.depth_atlas[(y * r.depth_width + x) * 2] = mean;
      r.depth_atlas[(y * r.depth_width + x) * 2 + 1] = mean * mean;
    }
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  const loader::Vec3 mid{-1.f + 0.75f, 0.f, -2.f}, n = unit(0, 1, 0);
  const float dim = v.sh_irradiance(0, n)[0], bright = v.sh_irradiance(1, n)[0];
  loader::SampleOptions no_vis = from_sh();
  no_vis.use_visibility = false;
  EXPECT_NEAR(v.sample_irradiance(mid, n, no_vis)[0], 0.5f * (dim + bright), 1e-3f * bright);
  EXPECT_LT(v.sample_irradiance(mid, n, from_sh())[0], dim * 1.1f);
}

TEST(Sampler, InactiveProbesAreSkipped) {
  DdgiResult r = test::make_ddgi(2, 1, 1, 1, 25, false);
  std::fill(r.offsets.begin(), r.offsets.end(), 0.f);
  r.states = {ProbeState::Active, ProbeState::Inactive};
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  const loader::Vec3 n = unit(0, 1, 0);
  const loader::Rgb s = v.sample_irradiance({0.f, 0.f, -2.f}, n), e = v.sh_irradiance(0, n);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s[k], e[k], 1e-4f * std::max(1.f, e[k]));
}

// The point halfway between probes 0 and 1 of a volume, and the unit axis from probe 1 to probe 0.
struct BetweenProbes {
  loader::Vec3 mid, axis;
};
BetweenProbes between_probes(const loader::DdgiVolume& v) {
  const auto p0 = v.probe_position(0), p1 = v.probe_position(1);
  return {{0.5f * (p0[0] + p1[0]), 0.5f * (p0[1] + p1[1]), 0.5f * (p0[2] + p1[2])},
          unit(p0[0] - p1[0], p0[1] - p1[1], p0[2] - p1[2])};
}

// The normal bias in cells is max(normal_bias, normal_bias_cells x the smallest spacing): the same
// weights as that bias given in metres, and the default. It decides visibility: probe 1 recorded
// its surroundings 0.01 m beyond the midpoint between the probes; the midpoint, facing away from
// probe 1, sees it with a 1 mm bias alone and is pushed behind that depth by 0.3 of a cell.
TEST(Sampler, NormalBiasInCells) {
  DdgiResult r = test::make_ddgi(2, 1, 1, 1, 25, true);
  std::fill(r.offsets.begin(), r.offsets.end(), 0.f);
  const float spacing = r.desc.spacing[0];
  const int side = kDepthTexels + 2;
  for (int y = 0; y < r.depth_height; ++y)
    for (int x = 0; x < r.depth_width; ++x) {
      const float mean = x >= side ? 0.5f * spacing + 0.01f : 50.f;
      r.depth_atlas[(y * r.depth_width + x) * 2] = mean;
      r.depth_atlas[(y * r.depth_width + x) * 2 + 1] = mean * mean;
    }
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  const auto [mid, n] = between_probes(v);
  // Probe 1 lies straight behind the point: DDGI's weights (no fade), so that the bias decides.
  loader::SampleOptions cells, metres, seed_only, defaults;
  for (loader::SampleOptions* o : {&cells, &metres, &seed_only, &defaults}) o->behind_fade = 0.f;
  cells.normal_bias = 0.f;
  cells.normal_bias_cells = 0.3f;
  metres.normal_bias = 0.3f * spacing;
  metres.normal_bias_cells = 0.f;
  seed_only.normal_bias = 0.001f;
  seed_only.normal_bias_cells = 0.f;
  const loader::Rgb a = v.sample_irradiance(mid, n, cells), b = v.sample_irradiance(mid, n, metres);
  const loader::Rgb d = v.sample_irradiance(mid, n, defaults);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a[k], b[k]);
    EXPECT_EQ(a[k], d[k]);
  }
  // Probe 1 alone in sight: the blend moves towards probe 0 once the bias hides probe 1.
  const float e0 = v.sh_irradiance(0, n)[0], e1 = v.sh_irradiance(1, n)[0];
  const float seed = v.sample_irradiance(mid, n, seed_only)[0];
  ASSERT_GT(std::fabs(e0 - e1), 1e-3f);
  EXPECT_LT(std::fabs(a[0] - e0), std::fabs(seed - e0));
}

// A probe behind the surface's tangent plane (cosine c < 0 between the normal and the direction to
// it) keeps saturate(1 + c / behind_fade) of DDGI's wrapped back-face weight, so past the fade the
// point reads the probe in front of it alone (to the weight floor); behind_fade 0 is DDGI's weight.
TEST(Sampler, ProbesBehindTheTangentPlaneFadeOut) {
  DdgiResult r = test::make_ddgi(2, 1, 1, 1, 27, /*atlases=*/false);
  std::fill(r.offsets.begin(), r.offsets.end(), 0.f);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  const auto [mid, u] = between_probes(v);
  const loader::Vec3 side = std::fabs(u[1]) < 0.9f ? loader::Vec3{0.f, 1.f, 0.f} : loader::Vec3{1.f, 0.f, 0.f};
  loader::Vec3 perp{side[1] * u[2] - side[2] * u[1], side[2] * u[0] - side[0] * u[2], side[0] * u[1] - side[1] * u[0]};
  perp = unit(perp[0], perp[1], perp[2]);
  loader::SampleOptions ddgi = from_sh();
  ddgi.behind_fade = 0.f;
  for (const float c : {0.1f, -0.05f, -0.1f, -0.19f, -0.25f, -0.6f}) {  // cosine towards probe 1
    const float s = std::sqrt(1.f - c * c);
    const loader::Vec3 n{-c * u[0] + s * perp[0], -c * u[1] + s * perp[1], -c * u[2] + s * perp[2]};
    loader::ProbeWeight faded[8], plain[8];
    ASSERT_EQ(v.probe_weights(mid, n, faded, from_sh()), 2u);
    ASSERT_EQ(v.probe_weights(mid, n, plain, ddgi), 2u);
    ASSERT_EQ(faded[1].probe, 1u);
    // Probe 0 at cosine -c, probe 1 at c: only the one behind the point fades.
    EXPECT_NEAR(faded[0].backface, plain[0].backface * std::clamp(1.f - c / 0.2f, 0.f, 1.f), 1e-6f) << c;
    EXPECT_NEAR(faded[1].backface, plain[1].backface * std::clamp(1.f + c / 0.2f, 0.f, 1.f), 1e-6f) << c;
    if (c <= -0.2f) {  // probe 0 alone, where DDGI's weights mix probe 1 in
      const loader::Rgb e = v.sample_irradiance(mid, n, from_sh()), front = v.sh_irradiance(0, n);
      const loader::Rgb mixed = v.sample_irradiance(mid, n, ddgi);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(e[k], front[k], 1e-4f * std::max(1.f, std::fabs(front[k]))) << c;
      EXPECT_GT(std::fabs(mixed[0] - front[0]), 0.01f * std::fabs(front[0])) << c;
    }
  }
}

// What the GLSL sampler is handed (gibake/ddgi_sample.glsl; the GPU comparison is
// tests/vulkan/ddgi_sample_glsl_test.cpp): the description, planes per row resolved, the formats
// of present sections, and the table index of each section an engine uploads.
TEST(Sampler, GlslVolumeAndSectionIndices) {
  DdgiResult r = test::make_ddgi(3, 4, 2, 1, 41);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_result(r, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  const loader::GlslDdgiVolume g = v.glsl_volume();
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(g.grid_min[a], v.desc().grid_min[a]);
    EXPECT_EQ(g.spacing[a], v.desc().spacing[a]);
    EXPECT_EQ(g.counts[a], v.desc().counts[a]);
  }
  EXPECT_EQ(g.counts[3], 4);
  EXPECT_EQ(g.atlas[0], 16u);
  EXPECT_EQ(g.atlas[1], 1u);
  EXPECT_EQ(g.atlas[2], 4u);  // Y: every plane in one band
  EXPECT_EQ(g.atlas[3], 1u | (8u << 8));  // a depth atlas; irradiance tiles of 8 texels
  EXPECT_EQ(g.formats[0], uint32_t(GIBAKE_FORMAT_F32));
  EXPECT_EQ(g.formats[1], uint32_t(GIBAKE_FORMAT_U8));
  EXPECT_EQ(g.formats[2], uint32_t(GIBAKE_FORMAT_RG32F));
  EXPECT_EQ(g.formats[3], 1u | (uint32_t(GIBAKE_FORMAT_RGBA32F) << 8));  // offsets; the irradiance format
  for (uint32_t type : {GIBAKE_SECTION_DDGI_VOLUME, GIBAKE_SECTION_DDGI_SH, GIBAKE_SECTION_DDGI_STATES,
                        GIBAKE_SECTION_DDGI_OFFSETS, GIBAKE_SECTION_DDGI_DEPTH}) {
    const int32_t i = v.section_index(type);
    ASSERT_GE(i, 0) << type;
    EXPECT_EQ(file.sections()[size_t(i)].type, type);
  }
  EXPECT_EQ(v.section_index(GIBAKE_SECTION_METADATA), -1);

  DdgiResult bare = test::make_ddgi(2, 2, 2, 2, 42, /*atlases=*/false);
  bare.offsets.clear();
  bare.states.clear();
  bare.stats.clear();
  std::vector<uint8_t> bare_bytes;
  const loader::BakeFile bare_file = open_result(bare, bare_bytes);
  const loader::DdgiVolume& b = bare_file.ddgi_volumes()[0];
  const loader::GlslDdgiVolume h = b.glsl_volume();
  EXPECT_EQ(h.atlas[3], 0u);
  EXPECT_EQ(h.formats[1], 0u);
  EXPECT_EQ(h.formats[3], 0u);
  EXPECT_EQ(b.section_index(GIBAKE_SECTION_DDGI_DEPTH), -1);
  EXPECT_EQ(b.section_index(GIBAKE_SECTION_DDGI_STATES), -1);
}

// LoadOptions::probe_major_tiles changes where the sampler reads a probe's texels, never what it
// reads: every answer is the atlases' to the bit, at binary16 and float32, with inactive probes,
// for the atlas and the SH, with and without visibility; and each active probe's block holds its
// atlas tile's texels.
TEST(Sampler, ProbeMajorTilesGiveTheAtlasesAnswersToTheBit) {
  for (const FloatPrecision precision : {FloatPrecision::Half, FloatPrecision::Full}) {
    const DdgiResult r = test::make_ddgi(4, 3, 3, 2, 61);
    BakeOutputs outputs;
    outputs.ddgi = &r;
    BakeFileOptions options;
    options.atlas = precision;
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(build_bake_file(outputs, options, bytes).is_ok());
    loader::BakeFile atlas, tiled;
    ASSERT_FALSE(atlas.open_borrowed(bytes.data(), bytes.size()));
    ASSERT_FALSE(tiled.open_borrowed(bytes.data(), bytes.size(), loader::LoadOptions{true, true}));
    const loader::DdgiVolume &a = atlas.ddgi_volumes()[0], &t = tiled.ddgi_volumes()[0];
    EXPECT_EQ(a.probe_tile_bytes(), 0u);
    EXPECT_GT(t.probe_tile_bytes(), 0u);
    const uint32_t depth_bytes = precision == FloatPrecision::Half ? 2u : 4u;
    EXPECT_EQ(t.probe_tile_element_bytes(true), depth_bytes);
    const gibake_ddgi_volume& d = t.desc();
    for (uint32_t probe = 0; probe < t.probe_count(); ++probe) {
      if (t.state(probe) == GIBAKE_PROBE_INACTIVE) {
        EXPECT_EQ(t.probe_tile(probe, true), nullptr) << probe;
        continue;
      }
      const uint8_t* block = t.probe_tile(probe, true);
      ASSERT_NE(block, nullptr) << probe;
      const uint32_t side = d.depth_tile + 2 * d.tile_border;
      const std::array<uint32_t, 2> origin = t.tile_origin(probe, d.depth_tile);
      for (uint32_t y = 0; y < side; ++y)
        for (uint32_t x = 0; x < side; ++x) {
          const std::array<float, 2> texel = t.depth_texel(origin[0] + x, origin[1] + y);
          for (uint32_t k = 0; k < 2; ++k) {
            const uint8_t* at = block + ((y * side + x) * 2 + k) * depth_bytes;
            float value;
            if (depth_bytes == 2) {
              uint16_t h;
              std::memcpy(&h, at, 2);
              value = loader::half_to_float(h);
            } else {
              std::memcpy(&value, at, 4);
            }
            ASSERT_EQ(value, texel[k]) << probe << " " << x << " " << y;
          }
        }
    }
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    for (int i = 0; i < 4000; ++i) {
      const loader::Vec3 p{-1.5f + 6.f * (u(rng) + 1.f), -0.5f + 1.5f * (u(rng) + 1.f), -2.5f + 3.f * (u(rng) + 1.f)};
      const loader::Vec3 n = unit(u(rng), u(rng), u(rng));
      loader::SampleOptions o;
      o.use_irradiance_atlas = i % 3 != 0;
      o.use_visibility = i % 4 != 0;
      loader::Rgb ea, et;
      const bool fa = a.try_sample_irradiance(p, n, ea, o), ft = t.try_sample_irradiance(p, n, et, o);
      ASSERT_EQ(fa, ft) << i;
      ASSERT_EQ(std::memcmp(ea.data(), et.data(), sizeof ea), 0) << i;
      loader::ProbeWeight wa[8], wt[8];
      const uint32_t ca = a.probe_weights(p, n, wa, o), ct = t.probe_weights(p, n, wt, o);
      ASSERT_EQ(ca, ct) << i;
      for (uint32_t k = 0; k < ca; ++k) {
        EXPECT_EQ(wa[k].probe, wt[k].probe);
        EXPECT_EQ(wa[k].weight, wt[k].weight);
      }
      for (uint32_t probe : {0u, 5u, 13u}) {
        const loader::Rgb xa = a.atlas_irradiance(probe, n), xt = t.atlas_irradiance(probe, n);
        ASSERT_EQ(std::memcmp(xa.data(), xt.data(), sizeof xa), 0) << i << " " << probe;
      }
    }
  }
}

}  // namespace
