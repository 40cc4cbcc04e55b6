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

// Shard 1 of 3 of a 520x1x2 grid (1040 probes, three blocks of up to 512: probes [512, 1024)), SH
// order 1, probe gather with 2 hits.
DdgiShard synthetic_shard() {
  DdgiShard s;
  s.desc.counts = {520, 1, 2};
  s.desc.grid_min = {0.f, 0.f, 0.f};
  s.desc.grid_max = {519.f, 0.f, 1.f};
  s.desc.spacing = {1.f, 0.f, 1.f};
  s.desc.sh_order = 1;
  s.desc.max_distance = 10.f;
  s.atlas_planes_per_row = 1;
  s.irradiance_width = 40, s.irradiance_height = 20, s.depth_width = 72, s.depth_height = 36;
  s.range = shard_range(1, 3, 1040);
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
  EXPECT_EQ(r.range.begin, 512u);
  EXPECT_EQ(r.range.end, 1024u);
  EXPECT_EQ(r.input_hash, s.input_hash);
  EXPECT_EQ(r.settings_hash, s.settings_hash);
  EXPECT_TRUE(r.probe_gather);
  EXPECT_EQ(r.sh0, s.sh0);
  EXPECT_EQ(r.irradiance, s.irradiance);
  EXPECT_EQ(r.depth_tiles, s.depth_tiles);
  EXPECT_EQ(r.bounce_hits, s.bounce_hits);
  ASSERT_EQ(r.probes.size(), 512u);
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
      {"range", [](DdgiShard& s) { s.range.end = 1023; }, "shard_info"},
      {"blocks", [](DdgiShard& s) { s.total_blocks = 4; }, "shard_info"},
      {"volume", [](DdgiShard& s) { s.volumes = 2; }, "shard_info"},
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

// Shards own whole blocks: every probe once, ranges on block boundaries, at most one block more
// than an even split; the same for volumes whose blocks are numbered one after the other.
TEST(ShardFile, RangesCoverEveryProbeOnceInWholeBlocks) {
  for (uint32_t probes : {1u, 7u, 13u, 60u, 513u, 1024u, 3841u, 100352u})
    for (uint32_t n : {1u, 2u, 3u, 7u, 17u, 64u}) {
      const uint32_t blocks = probe_blocks(probes);
      uint32_t next = 0;
      for (uint32_t i = 0; i < n; ++i) {
        const ShardRange r = shard_range(i, n, probes);
        EXPECT_EQ(r.begin, next);
        EXPECT_GE(r.end, r.begin);
        EXPECT_EQ(r.begin % kProbeBlock, 0u);
        EXPECT_TRUE(r.end == probes || r.end % kProbeBlock == 0);
        EXPECT_LE(r.end - r.begin, (blocks / n + 1) * kProbeBlock);
        next = r.end;
      }
      EXPECT_EQ(next, probes);
    }
  const std::vector<uint32_t> volumes = {700, 13, 1500, 512};  // blocks 2, 1, 3, 1
  const uint32_t total = 7;
  for (uint32_t n : {1u, 2u, 3u, 7u, 9u}) {
    std::vector<uint32_t> next(volumes.size(), 0);
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t first = 0, owned = 0;
      for (size_t v = 0; v < volumes.size(); ++v) {
        const ShardRange r = shard_range(i, n, volumes[v], first, total);
        EXPECT_EQ(r.begin, next[v]) << "volume " << v << ", shard " << i << " of " << n;
        next[v] = r.end;
        if (r.end > r.begin) owned += probe_blocks(r.end) - r.begin / kProbeBlock;
        first += probe_blocks(volumes[v]);
      }
      EXPECT_EQ(owned, total * (i + 1) / n - total * i / n) << "shard " << i << " of " << n;
    }
    for (size_t v = 0; v < volumes.size(); ++v) EXPECT_EQ(next[v], volumes[v]);
  }
}

// A shard of a bake of two volumes: one set of sections per volume, each in its info's group.
TEST(ShardFile, TwoVolumesRoundTrip) {
  std::vector<DdgiShard> volumes = {synthetic_shard(), synthetic_shard()};
  // The second volume: 4x1x2 probes, the bake's fourth block; shard 1 of 3 owns blocks [1, 2).
  DdgiShard& b = volumes[1];
  b.desc.counts = {4, 1, 2};
  b.desc.grid_max = {3.f, 0.f, 1.f};
  for (DdgiShard& v : volumes) v.volumes = 2, v.total_blocks = 4;
  b.volume = 1;
  b.first_block = 3;
  b.range = shard_range(1, 3, 8, 3, 4);
  ASSERT_EQ(b.range.end, 0u);  // shard 1 owns none of it
  b.probes.clear();
  b.sh0.clear();
  b.irradiance.clear();
  b.depth_tiles.clear();
  b.bounce_hits.clear();
  volumes[0].range = shard_range(1, 3, 1040, 0, 4);
  ASSERT_EQ(volumes[0].range.begin, 512u);
  ASSERT_EQ(volumes[0].range.end, 1024u);
  std::vector<DdgiShard> written = volumes;
  const fs::path path = temp_file("two_volumes");
  ASSERT_TRUE(write_shard_file(path.string(), written, nullptr, BakeFileOptions{}, {}).is_ok());
  std::vector<DdgiShard> r;
  Status st = read_shard_volumes(path.string(), r, nullptr);
  ASSERT_TRUE(st.is_ok()) << st.message();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].range.begin, 512u);
  EXPECT_EQ(r[0].sh0, volumes[0].sh0);
  EXPECT_EQ(r[0].bounce_hits, volumes[0].bounce_hits);
  EXPECT_EQ(r[1].desc.counts, b.desc.counts);
  EXPECT_EQ(r[1].first_block, 3u);
  EXPECT_TRUE(r[1].probes.empty());
  // Volumes out of order (the second's blocks not after the first's) are refused.
  written = volumes;
  written[1].first_block = 2;
  written[1].range = shard_range(1, 3, 8, 2, 4);
  ASSERT_TRUE(write_shard_file(path.string(), written, nullptr, BakeFileOptions{}, {}).is_ok());
  st = read_shard_volumes(path.string(), r, nullptr);
  EXPECT_EQ(st.code(), ExitCode::InvalidInput);
  EXPECT_EQ(st.where(), "shard_info") << st.message();
  fs::remove(path);
}

}  // namespace
