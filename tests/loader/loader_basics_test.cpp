// Loader-only tests: XXH64 equals libxxhash, float16 conversions, garbage and corpus robustness.
#include <gtest/gtest.h>
#include <xxhash.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "gibake/loader.hpp"

namespace {

using namespace gibake::loader;

TEST(LoaderHash, Xxh64MatchesLibxxhashOnManyLengths) {
  std::mt19937_64 rng(42);
  std::vector<uint8_t> buffer(5000);
  for (uint8_t& b : buffer) b = uint8_t(rng());
  for (size_t len = 0; len <= 300; ++len) {
    for (uint64_t seed : {uint64_t(0), uint64_t(1), uint64_t(0x9E3779B97F4A7C15ULL)}) {
      ASSERT_EQ(xxh64(buffer.data(), len, seed), XXH64(buffer.data(), len, seed)) << "len " << len;
    }
  }
  for (size_t len : {511u, 512u, 1023u, 4096u, 4999u, 5000u}) {
    for (size_t start : {0u, 1u, 3u, 7u}) {  // unaligned starts
      if (start + len <= buffer.size()) {
        ASSERT_EQ(xxh64(buffer.data() + start, len, 7), XXH64(buffer.data() + start, len, 7)) << len;
      }
    }
  }
  std::vector<uint8_t> big(3 << 20);
  for (uint8_t& b : big) b = uint8_t(rng());
  EXPECT_EQ(xxh64(big.data(), big.size(), 0), XXH64(big.data(), big.size(), 0));
}

TEST(LoaderHalf, EveryHalfRoundTrips) {
  for (uint32_t h = 0; h < 65536; ++h) {
    const float f = half_to_float(uint16_t(h));
    if (std::isnan(f)) {
      EXPECT_TRUE(std::isnan(half_to_float(float_to_half(f))));
      continue;
    }
    ASSERT_EQ(float_to_half(f), uint16_t(h)) << h;
  }
}

TEST(LoaderHalf, QuantisationErrorWithinHalfUlp) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> e(-14.f, 15.9f);
  for (int i = 0; i < 200000; ++i) {
    const float f = std::exp2(e(rng)) * (i % 2 ? 1.f : -1.f);
    const float back = half_to_float(float_to_half(f));
    ASSERT_LE(std::fabs(back - f), std::fabs(f) * std::exp2(-11.f)) << f;
  }
  EXPECT_EQ(half_to_float(float_to_half(65504.f)), 65504.f);
  EXPECT_TRUE(std::isinf(half_to_float(float_to_half(70000.f))));
  EXPECT_EQ(half_to_float(float_to_half(0.5f)), 0.5f);
  EXPECT_EQ(half_to_float(float_to_half(std::exp2(-24.f))), std::exp2(-24.f));  // smallest subnormal
}

TEST(LoaderRobustness, RandomBytesAndHeadersNeverCrash) {
  std::mt19937 rng(11);
  for (int i = 0; i < 2000; ++i) {
    std::vector<uint8_t> bytes(rng() % 600);
    for (uint8_t& b : bytes) b = uint8_t(rng());
    if (bytes.size() >= 8 && i % 2) std::memcpy(bytes.data(), GIBAKE_MAGIC_BYTES, 8);
    BakeFile file;
    const Error e = file.open_borrowed(bytes.data(), bytes.size(), LoadOptions{false});
    EXPECT_TRUE(e) << "random bytes accepted";
    EXPECT_FALSE(e.message.empty());
  }
  BakeFile empty;
  EXPECT_EQ(empty.open_borrowed(nullptr, 0).code, ErrorCode::Truncated);
  EXPECT_EQ(empty.open("/nonexistent/file.bin").code, ErrorCode::IoError);
}

// Replays tests/loader/corpus (valid seeds and files the fuzzer found) through the loader.
// Each corpus file is named after what the loader must say about it. The fuzzer-made files also
// carry stale checksums, so their structural error is the one reported with checksums skipped.
TEST(LoaderCorpus, EachFileGivesItsDocumentedResult) {
  const std::filesystem::path dir = std::filesystem::path(GIBAKE_SOURCE_DIR) / "tests/loader/corpus";
  const std::pair<const char*, ErrorCode> expected[] = {
      {"fuzz_bad_element_format.bin", ErrorCode::BadElementFormat},
      {"fuzz_bad_section_table.bin", ErrorCode::BadSectionTable},
      {"fuzz_bad_volume.bin", ErrorCode::BadVolume},
      {"fuzz_missing_section.bin", ErrorCode::MissingSection},
      {"fuzz_section_out_of_range.bin", ErrorCode::SectionOutOfRange},
      {"fuzz_section_overlap.bin", ErrorCode::SectionOverlap},
      {"example_2x1x1_l1.bin", ErrorCode::Ok},
      {"small_1x2x1_l2_f32.bin", ErrorCode::Ok},
      {"small_2x1x1_l2_atlas16.bin", ErrorCode::Ok},
      {"tiny_1x1x1_l1_f16.bin", ErrorCode::Ok},
      {"sparse_5x1x2_l1_atlas16.bin", ErrorCode::Ok},
      {"lpv_2x1x1_l1_3x2x2_2cascades.bin", ErrorCode::Ok},
      {"fuzz_lpv_bad_volume.bin", ErrorCode::BadVolume},
      {"fuzz_lpv_missing_section.bin", ErrorCode::MissingSection},
  };
  for (const auto& [name, code] : expected) {
    const bool fuzzed = std::string(name).rfind("fuzz_", 0) == 0;
    BakeFile file;
    EXPECT_EQ(file.open((dir / name).string(), LoadOptions{!fuzzed}).code, code) << name;
    if (fuzzed) {
      EXPECT_NE(file.open((dir / name).string()).code, ErrorCode::Ok) << name;
    }
  }
  // Valid structure, wrong checksum: refused by default, accepted when checksums are skipped.
  BakeFile mutated;
  EXPECT_NE(mutated.open((dir / "fuzz_mutated_unchecked_ok.bin").string()).code, ErrorCode::Ok);
  EXPECT_EQ(mutated.open((dir / "fuzz_mutated_unchecked_ok.bin").string(), LoadOptions{false}).code, ErrorCode::Ok);
}

TEST(LoaderCorpus, ReplayNeverCrashes) {
  const std::filesystem::path dir = std::filesystem::path(GIBAKE_SOURCE_DIR) / "tests/loader/corpus";
  size_t files = 0, valid = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    ++files;
    std::ifstream in(entry.path(), std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (bool checksums : {true, false}) {
      BakeFile file;
      if (file.open_borrowed(bytes.data(), bytes.size(), LoadOptions{checksums})) continue;
      valid += checksums;
      for (const DdgiVolume& v : file.ddgi_volumes()) {
        for (uint32_t p = 0; p < v.probe_count(); ++p) (void)v.sh_irradiance(p, {0.f, 1.f, 0.f});
        const gibake_ddgi_volume& d = v.desc();
        for (float t : {-1.f, 0.f, 0.37f, 1.f, 2.f}) {
          Vec3 pos{d.grid_min[0] + t * (d.grid_max[0] - d.grid_min[0]), d.grid_min[1] + t, d.grid_min[2]};
          const Rgb e = v.sample_irradiance(pos, {0.f, 0.f, 1.f});
          for (float c : e) EXPECT_GE(c, 0.f);
        }
      }
      for (const LpvCascade& c : file.lpv_cascades())
        for (float t : {-1.f, 0.f, 0.37f, 1.f, 2.f}) {
          const gibake_lpv_cascade& d = c.desc();
          const Vec3 pos{d.grid_min[0] + t * float(d.dims[0]) * d.cell_size, d.grid_min[1] + t, d.grid_min[2]};
          for (float e : file.sample_lpv(pos, {0.f, 0.f, 1.f})) EXPECT_GE(e, 0.f);
        }
      (void)file.metadata_json();
    }
  }
  EXPECT_GE(files, 3u);
  EXPECT_GE(valid, 1u);
}

}  // namespace
