// Shard files at the library level (io/bakefile/bake_shard.h): a synthetic shard survives the
// round trip bit for bit, a runtime loader opens it as a file without volumes, and parts whose
// checksums are right but whose content does not hold together are refused, naming the section.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "gibake/format.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_shard.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake;

// Shard 1 of 3 of a 4x1x2 grid (probes [2, 5)), SH order 1, probe gather with 2 hits.
DdgiShard synthetic_shard() {
  DdgiShard s;
  s.desc.counts = {4, 1, 2};
  s.desc.grid_min = {0.f, 0.f, 0.f};
  s.desc.grid_max = {3.f, 0.f, 1.f};
  s.desc.spacing = {1.f, 0.f, 1.f};
  s.desc.sh_order = 1;
  s.desc.max_distance = 10.f;
  s.atlas_planes_per_row = 1;
  s.irradiance_width = 40, s.irradiance_height = 20, s.depth_width = 72, s.depth_height = 36;
  s.range = shard_range(1, 3, 8);
  s.input_hash = 0x1234;
  s.probe_gather = true;
  const std::string settings = R"({"gather":"probes","rays":8})";
  s.metadata_json = R"({"tool":"gibake","settings":)" + settings + "}";
  s.settings_hash = hash_settings(settings);
  const size_t n = s.range.end - s.range.begin;
  s.probes.resize(n);
  for (size_t i = 0; i < n; ++i) {
    s.probes[i].offset[0] = 0.1f * float(i);
    s.probes[i].stats.rays = uint32_t(8 + i);
    s.probes[i].integrated_rays = 8;
    s.probes[i].primary_rays = 8;
    s.probes[i].sky_only = i == 2;
  }
  s.probes[0].bounce_hits = 2;
  s.sh0.assign(n * 4 * 3, 0.5f);
  s.irradiance.assign(n * 64 * 3, 1.5f);
  s.depth_tiles.assign(n * 18 * 18 * 2, 2.5f);
  s.bounce_hits.assign(2 * kShardHitFloats, 0.25f);
  return s;
}

fs::path temp_file(const std::string& name) {
  return gibake::test::process_tmp() / ("shard_file_" + name + ".gibake");
}

TEST(ShardFile, RoundTripsAndLoadsAsAFileWithoutVolumes) {
  const DdgiShard s = synthetic_shard();
  DdgiShard written = s;  // the writer releases the arrays it encodes
  const fs::path path = temp_file("roundtrip");
  ASSERT_TRUE(write_shard_file(path.string(), written, nullptr, BakeFileOptions{}, {}).is_ok());
  EXPECT_TRUE(written.sh0.empty() && written.depth_tiles.empty() && written.probes.empty());
  DdgiShard r;
  const Status st = read_shard_file(path.string(), r, nullptr);
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_EQ(r.range.index, 1u);
  EXPECT_EQ(r.range.begin, 2u);
  EXPECT_EQ(r.range.end, 5u);
  EXPECT_EQ(r.input_hash, s.input_hash);
  EXPECT_EQ(r.settings_hash, s.settings_hash);
  EXPECT_TRUE(r.probe_gather);
  EXPECT_EQ(r.sh0, s.sh0);
  EXPECT_EQ(r.irradiance, s.irradiance);
  EXPECT_EQ(r.depth_tiles, s.depth_tiles);
  EXPECT_EQ(r.bounce_hits, s.bounce_hits);
  ASSERT_EQ(r.probes.size(), 3u);
  EXPECT_TRUE(r.probes[2].sky_only);
  EXPECT_EQ(r.probes[1].stats.rays, 9u);
  EXPECT_FLOAT_EQ(r.probes[2].offset[0], 0.2f);
  loader::BakeFile f;
  ASSERT_FALSE(f.open(path.string())) << "a runtime loader opens a shard file";
  EXPECT_TRUE(f.ddgi_volumes().empty());
  EXPECT_EQ(f.header().input_hash, s.input_hash);
  fs::remove(path);
}

// Written with valid checksums, so only the shard reader's own checks can catch them.
TEST(ShardFile, InconsistentPartsAreRefusedNamingTheSection) {
  struct Case {
    const char* name;
    void (*spoil)(DdgiShard&);
    const char* where;
  };
  const Case cases[] = {
      {"range", [](DdgiShard& s) { s.range.end = 6; }, "shard_info"},
      {"index", [](DdgiShard& s) { s.range.index = 3; }, "shard_info"},
      {"counts", [](DdgiShard& s) { s.desc.counts[0] = 0; }, "shard_info"},
      {"sh0", [](DdgiShard& s) { s.sh0.pop_back(); }, "shard_sh0"},
      {"depth", [](DdgiShard& s) { s.depth_tiles.resize(s.depth_tiles.size() - 2); }, "shard_depth"},
      {"hits", [](DdgiShard& s) { s.probes[1].bounce_hits = 1; }, "shard_probes"},
      {"probes", [](DdgiShard& s) { s.probes.pop_back(); }, "shard_probes"},
      {"settings", [](DdgiShard& s) { s.settings_hash ^= 1; }, "metadata"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    DdgiShard s = synthetic_shard();
    c.spoil(s);
    const fs::path path = temp_file(c.name);
    ASSERT_TRUE(write_shard_file(path.string(), s, nullptr, BakeFileOptions{}, {}).is_ok());
    DdgiShard r;
    const Status st = read_shard_file(path.string(), r, nullptr);
    EXPECT_EQ(st.code(), ExitCode::InvalidInput);
    EXPECT_EQ(st.file(), path.string());
    EXPECT_EQ(st.where(), c.where) << st.message();
    fs::remove(path);
  }
}

TEST(ShardFile, RangesCoverEveryProbeOnce) {
  for (uint32_t probes : {1u, 7u, 13u, 60u, 100352u})
    for (uint32_t n : {1u, 2u, 3u, 7u, 17u, 64u}) {
      uint32_t next = 0;
      for (uint32_t i = 0; i < n; ++i) {
        const ShardRange r = shard_range(i, n, probes);
        EXPECT_EQ(r.begin, next);
        EXPECT_GE(r.end, r.begin);
        EXPECT_LE(r.end - r.begin, probes / n + 1);
        next = r.end;
      }
      EXPECT_EQ(next, probes);
    }
}

}  // namespace
