// Sparse DDGI volumes (format 1.5): the writer stores only the probes that are not Inactive, and
// every loader call answers as for the same volume stored dense, to the bit; malformed slot maps
// are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>

#include "io/bakefile/bake_file.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;

std::vector<uint8_t> build(const DdgiResult& r) { return test::one_volume_file(r, FloatPrecision::Full); }

// Most probes inactive, as in a near-surface volume, and a wrapped atlas (k = 2 of Y = 5).
DdgiResult mostly_inactive(uint32_t seed) {
  DdgiResult r = test::make_ddgi(6, 5, 4, 2, seed);
  std::mt19937 rng(seed);
  for (ProbeState& s : r.states) s = rng() % 3 == 0 ? ProbeState::Active : ProbeState::Inactive;
  r.states[7] = ProbeState::SkyOnly;
  // Re-lay the atlases for k = 2: 3 bands of 2, 2, 1 planes.
  r.atlas_planes_per_row = 2;
  r.irradiance_width = 6 * 2 * (kIrradianceTexels + 2);
  r.irradiance_height = 4 * 3 * (kIrradianceTexels + 2);
  r.depth_width = 6 * 2 * (kDepthTexels + 2);
  r.depth_height = 4 * 3 * (kDepthTexels + 2);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  r.irradiance_atlas.clear();
  for (int i = 0; i < r.irradiance_width * r.irradiance_height; ++i)
    r.irradiance_atlas.insert(r.irradiance_atlas.end(), {100.f * u(rng), 80.f * u(rng), 60.f * u(rng), 1.f});
  r.depth_atlas.clear();
  for (int i = 0; i < r.depth_width * r.depth_height; ++i) {
    const float mean = 0.5f + 3.f * u(rng);
    r.depth_atlas.insert(r.depth_atlas.end(), {mean, mean * mean + 0.05f * u(rng)});
  }
  return r;
}

uint32_t bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

TEST(SparseVolume, ReadsAsTheDenseVolumeToTheBit) {
  DdgiResult r = mostly_inactive(7);
  const std::vector<uint8_t> dense_bytes = build(r);
  r.sparse = true;
  const std::vector<uint8_t> sparse_bytes = build(r);
  loader::BakeFile dense, sparse;
  ASSERT_FALSE(dense.open_borrowed(dense_bytes.data(), dense_bytes.size()));
  const loader::Error e = sparse.open_borrowed(sparse_bytes.data(), sparse_bytes.size());
  ASSERT_FALSE(e) << e.message;
  EXPECT_EQ(dense.header().version_minor, 2u);
  EXPECT_EQ(sparse.header().version_minor, 5u);
  const loader::DdgiVolume &a = dense.ddgi_volumes()[0], &b = sparse.ddgi_volumes()[0];
  EXPECT_FALSE(a.sparse());
  ASSERT_TRUE(b.sparse());
  uint32_t kept = 0;
  for (ProbeState s : r.states) kept += s != ProbeState::Inactive;
  EXPECT_EQ(b.stored_probes(), kept);
  EXPECT_LT(kept, a.probe_count() / 2);
  EXPECT_LT(sparse_bytes.size(), dense_bytes.size() / 2 + 4096);
  for (uint32_t p = 0; p < a.probe_count(); ++p) {
    ASSERT_EQ(a.state(p), b.state(p)) << p;
    if (a.state(p) == GIBAKE_PROBE_INACTIVE) {
      EXPECT_EQ(b.slot(p), GIBAKE_PROBE_SLOT_NONE);
      continue;
    }
    for (uint32_t c = 0; c < 9; ++c)
      for (uint32_t k = 0; k < 3; ++k) ASSERT_EQ(bits(a.sh(p, c, k)), bits(b.sh(p, c, k)));
    for (uint32_t k = 0; k < 3; ++k) EXPECT_EQ(bits(a.offset(p)[k]), bits(b.offset(p)[k]));
    EXPECT_EQ(a.stats(p).rays, b.stats(p).rays);
    // The probe's whole bordered tiles, texel by texel, in either atlas.
    for (const bool depth : {false, true}) {
      const uint32_t interior = depth ? a.desc().depth_tile : a.desc().irradiance_tile;
      const std::array<uint32_t, 2> ta = a.tile_origin(p, interior), tb = b.tile_origin(p, interior);
      for (uint32_t y = 0; y < interior + 2; ++y)
        for (uint32_t x = 0; x < interior + 2; ++x) {
          if (depth) {
            ASSERT_EQ(a.depth_texel(ta[0] + x, ta[1] + y), b.depth_texel(tb[0] + x, tb[1] + y)) << p;
          } else {
            ASSERT_EQ(a.irradiance_texel(ta[0] + x, ta[1] + y), b.irradiance_texel(tb[0] + x, tb[1] + y)) << p;
          }
        }
    }
  }
  // Sampling: points over the grid and beyond, through the atlas and the SH; the probe-major tile
  // copies give the sparse file's answer to the bit. Against the dense file within 1e-3 relative:
  // the sampler computes its bilinear weights in atlas coordinates, which round with the tile's
  // place in the atlas (by up to 2^-10 texel at 16384), and the Chebyshev weight's cube and these
  // random texels (neighbours differ by up to 100%) pass that on.
  loader::BakeFile sparse_tiles;
  ASSERT_FALSE(sparse_tiles.open_borrowed(sparse_bytes.data(), sparse_bytes.size(), loader::LoadOptions{true, true}));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.3f, 1.3f);
  size_t answered = 0, differ = 0;
  float worst = 0.f;
  loader::SampleOptions sh;
  sh.use_irradiance_atlas = false;
  for (int i = 0; i < 3000; ++i) {
    const loader::Vec3 p{-1.f + 7.5f * u(rng), 4.f * u(rng), -2.f + 6.f * u(rng)};
    loader::Vec3 n{u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f};
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (float& c : n) c /= len;
    for (const loader::SampleOptions& o : {loader::SampleOptions{}, sh}) {
      loader::Rgb ea{}, eb{}, ec{};
      const bool fa = a.try_sample_irradiance(p, n, ea, o);
      ASSERT_EQ(fa, b.try_sample_irradiance(p, n, eb, o));
      ASSERT_EQ(fa, sparse_tiles.ddgi_volumes()[0].try_sample_irradiance(p, n, ec, o));
      for (int k = 0; k < 3; ++k) {
        ASSERT_NEAR(ea[k], eb[k], 1e-3f * ea[k]) << i;
        worst = std::max(worst, std::fabs(ea[k] - eb[k]) / ea[k]);
        ASSERT_EQ(bits(eb[k]), bits(ec[k])) << i;
        differ += bits(ea[k]) != bits(eb[k]);
      }
      answered += fa;
    }
  }
  EXPECT_GT(answered, 3000u);
  std::printf("%zu of %zu values differ from the dense file's, by %.3g relative at most\n", differ, answered * 3,
              double(worst));
}

TEST(SparseVolume, AVolumeWithNothingStoredStaysDense) {
  DdgiResult r = test::make_ddgi(3, 2, 2, 1, 9);
  for (ProbeState& s : r.states) s = ProbeState::Inactive;
  r.sparse = true;
  const std::vector<uint8_t> bytes = build(r);
  loader::BakeFile f;
  ASSERT_FALSE(f.open_borrowed(bytes.data(), bytes.size()));
  EXPECT_FALSE(f.ddgi_volumes()[0].sparse());
  EXPECT_EQ(f.header().version_minor, 2u);
}

// The sparse file with one edit to its volume record or slot map, resealed (checksums fixed).
std::vector<uint8_t> edited(const std::vector<uint8_t>& bytes, const std::function<void(gibake_ddgi_volume&)>& desc,
                            const std::function<void(uint32_t*, size_t)>& slots) {
  std::vector<uint8_t> out = bytes;
  gibake_file_header h;
  std::memcpy(&h, out.data(), sizeof h);
  for (uint32_t i = 0; i < h.section_count; ++i) {
    gibake_section_entry* e = test::table_entry(out, i);
    uint8_t* payload = out.data() + e->offset;
    if (e->type == GIBAKE_SECTION_DDGI_VOLUME && desc) {
      gibake_ddgi_volume d;
      std::memcpy(&d, payload, sizeof d);
      desc(d);
      std::memcpy(payload, &d, sizeof d);
    } else if (e->type == GIBAKE_SECTION_DDGI_PROBE_SLOTS && slots) {
      std::vector<uint32_t> words(size_t(e->count));
      std::memcpy(words.data(), payload, words.size() * 4);
      slots(words.data(), words.size());
      std::memcpy(payload, words.data(), words.size() * 4);
    } else {
      continue;
    }
    e->checksum = loader::xxh64(payload, size_t(e->size), 0);
  }
  test::reseal(out);
  return out;
}

TEST(SparseVolume, MalformedSlotMapsAreRefused) {
  DdgiResult r = mostly_inactive(11);
  r.sparse = true;
  const std::vector<uint8_t> good = build(r);
  auto code = [](const std::vector<uint8_t>& bytes, std::string* message = nullptr) {
    loader::BakeFile f;
    const loader::Error e = f.open_borrowed(bytes.data(), bytes.size());
    if (message) *message = e.message;
    return e.code;
  };
  ASSERT_EQ(code(good), loader::ErrorCode::Ok);
  const auto first_two = [](uint32_t* w, size_t n, auto f) {
    size_t a = n, b = n;
    for (size_t i = 0; i < n; ++i)
      if (w[i] != GIBAKE_PROBE_SLOT_NONE) {
        if (a == n)
          a = i;
        else if (b == n)
          b = i;
      }
    f(w, a, b);
  };
  std::string message;
  // Two probes swapped: slots out of probe order.
  EXPECT_EQ(code(edited(good, {},
                        [&](uint32_t* w, size_t n) {
                          first_two(w, n, [](uint32_t* w, size_t a, size_t b) { std::swap(w[a], w[b]); });
                        }),
                 &message),
            loader::ErrorCode::BadVolume);
  EXPECT_NE(message.find("slots in probe order"), std::string::npos) << message;
  // A slot beyond stored_probes, and one probe dropped (fewer slots than stored_probes).
  EXPECT_EQ(code(edited(good, {},
                        [](uint32_t* w, size_t n) {
                          for (size_t i = n; i-- > 0;)
                            if (w[i] != GIBAKE_PROBE_SLOT_NONE) {
                              w[i] = 0x7FFFFFFFu;
                              break;
                            }
                        })),
            loader::ErrorCode::BadVolume);
  EXPECT_EQ(code(edited(good, {},
                        [](uint32_t* w, size_t n) {
                          for (size_t i = n; i-- > 0;)
                            if (w[i] != GIBAKE_PROBE_SLOT_NONE) {
                              w[i] = GIBAKE_PROBE_SLOT_NONE;
                              break;
                            }
                        }),
                 &message),
            loader::ErrorCode::BadVolume);
  EXPECT_NE(message.find("stored_probes"), std::string::npos) << message;
  // The record: stored_probes past the probes, no tiles a row, planes per row set, an unknown flag,
  // the sparse flag cleared (the slot map then belongs to a dense volume, whose counts differ).
  for (const auto& edit : std::vector<std::function<void(gibake_ddgi_volume&)>>{
           [](gibake_ddgi_volume& d) { d.stored_probes = d.probe_count + 1; },
           [](gibake_ddgi_volume& d) { d.atlas_tiles_per_row = 0; },
           [](gibake_ddgi_volume& d) { d.atlas_planes_per_row = 1; }, [](gibake_ddgi_volume& d) { d.flags |= 2u; },
           [](gibake_ddgi_volume& d) { d.flags = 0; }, [](gibake_ddgi_volume& d) { d.atlas_tiles_per_row += 1; }})
    EXPECT_EQ(code(edited(good, edit, {})), loader::ErrorCode::BadVolume);
  // A sparse volume without its slot map (its section's type changed to an unknown one: skipped).
  std::vector<uint8_t> no_map = good;
  gibake_file_header h;
  std::memcpy(&h, no_map.data(), sizeof h);
  for (uint32_t i = 0; i < h.section_count; ++i)
    if (test::table_entry(no_map, i)->type == GIBAKE_SECTION_DDGI_PROBE_SLOTS) test::table_entry(no_map, i)->type = 40;
  test::reseal(no_map);
  EXPECT_EQ(code(no_map), loader::ErrorCode::MissingSection);
}

}  // namespace
