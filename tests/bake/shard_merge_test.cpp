// Sharded bakes end to end: `gibake bake --shard I/N` + `gibake merge` give the bytes of the bake
// made in one go (both gathers, the probe filter, --target-error with the ray budget, several probe
// volumes, refinement by check finished with --from-shards, LPV, any
// part order and thread count, CPU and lavapipe), and every bad set of parts is refused with one
// line naming it, exit code 3 and no output. Shards own whole blocks of 512 probes, so the grids
// here have several blocks, and shard counts above the blocks leave shards empty.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "io/bakefile/bake_shard.h"
#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using gibake::test::CliResult;
using gibake::test::run_gibake_cli;
using gibake::test::shell_quote;

const std::string kCornell = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
const std::string kBlocks = std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/cornell_blocks.gltf";

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = gibake::test::process_tmp() / ("shard_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string part(const fs::path& dir, uint32_t i) { return (dir / ("part_" + std::to_string(i) + ".gibake")).string(); }

// How the parts are finished: `gibake merge`, or the bake's own command with --from-shards (a bake
// that refines by check or fits its atlases to the surfaces, as the default does). Parts that
// `gibake merge` finishes are baked with --surface-fit off.
enum class Finish { Merge, FromShards };

// Bakes `options` whole and as `n` shards, merges the parts (in reverse order) and compares bytes.
void expect_identity(const fs::path& dir, const std::string& scene, const std::string& options, uint32_t n,
                     const std::string& merge_options = "", Finish finish = Finish::Merge) {
  SCOPED_TRACE(options + " as " + std::to_string(n) + " shards");
  const std::string base = shell_quote(scene) + " --ddgi " + options +
                           (finish == Finish::Merge ? " --surface-fit off" : "") + " --progress lines";
  const fs::path full = dir / "full.gibake", merged = dir / "merged.gibake";
  CliResult r = run_gibake_cli(base + " --out " + shell_quote(full.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string parts;
  for (uint32_t i = 0; i < n; ++i) {
    r = run_gibake_cli(base + " --shard " + std::to_string(i) + "/" + std::to_string(n) + " --out " + part(dir, i));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    parts = part(dir, i) + " " + parts;
  }
  const std::string finisher = finish == Finish::Merge ? "merge " + parts : base + " --from-shards " + parts;
  r = run_gibake_cli(finisher + " --out " + shell_quote(merged.string()) + " " + merge_options);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(bytes_of(full) == bytes_of(merged)) << "merged file differs from the unsharded bake";
  for (uint32_t i = 0; i < n; ++i) fs::remove(part(dir, i));
}

// 1280 probes: blocks of 512, 512 and 256, so 2 and 3 shards split it unevenly and 7 leave 4 empty.
const char* kGrid = "--probe-counts 16,16,5 --rays 16 --bounces 2";

TEST(ShardMerge, PathGatherIsByteIdenticalForAnyShardCount) {
  const fs::path dir = fresh_dir("path");
  for (uint32_t n : {1u, 2u, 3u, 7u}) expect_identity(dir, kCornell, kGrid, n);
  fs::remove_all(dir);
}

TEST(ShardMerge, ProbeGatherIsByteIdenticalForAnyShardCount) {
  const fs::path dir = fresh_dir("probes");
  for (uint32_t n : {1u, 2u, 3u, 7u}) expect_identity(dir, kCornell, std::string(kGrid) + " --gather probes", n);
  fs::remove_all(dir);
}

// The probe filter reads neighbours across shard boundaries, so it runs in the merge: the same bytes
// as the one-go bake that filtered after its trace.
TEST(ShardMerge, ProbeFilterIsByteIdenticalForAnyShardCount) {
  const fs::path dir = fresh_dir("filter");
  for (uint32_t n : {2u, 3u}) expect_identity(dir, kCornell, std::string(kGrid) + " --probe-filter on", n);
  fs::remove_all(dir);
}

// 13 probes (prime) in 7 shards, and more shards than probes (empty shards); adaptive rays.
TEST(ShardMerge, PrimeProbeCountTargetErrorAndEmptyShards) {
  const fs::path dir = fresh_dir("prime");
  const std::string grid = "--probe-counts 1,1,13 --rays 16 --target-error 0.05 --max-rays 128";
  expect_identity(dir, kCornell, grid, 7);
  expect_identity(dir, kCornell, grid + " --gather probes", 17, "--threads 1");
  fs::remove_all(dir);
}

// The ray budget is decided per block of probes, so the adaptive bake with a budget that binds
// (--max-rays 256 above its mean of 48) merges to the one-go bake's bytes for any shard count,
// more shards than blocks included; without the budget the bake is another (the budget bound).
TEST(ShardMerge, BudgetedAdaptiveBakeIsByteIdenticalForAnyShardCount) {
  const fs::path dir = fresh_dir("budget");
  const std::string grid = "--probe-counts 16,16,5 --rays 16 --target-error 0.02 --max-rays 256";
  for (uint32_t n : {1u, 2u, 3u, 7u}) expect_identity(dir, kCornell, grid + " --ray-budget 48", n);
  const std::string base = shell_quote(kCornell) + " --ddgi " + grid + " --progress lines --out ";
  const fs::path budget = dir / "budget.gibake", unbounded = dir / "unbounded.gibake";
  ASSERT_EQ(run_gibake_cli(base + shell_quote(budget.string()) + " --ray-budget 48").exit_code, 0);
  ASSERT_EQ(run_gibake_cli(base + shell_quote(unbounded.string()) + " --ray-budget 0").exit_code, 0);
  EXPECT_NE(bytes_of(budget), bytes_of(unbounded)) << "the budget did not bind: the test shows nothing";
  fs::remove_all(dir);
}

// Final's storage: without the irradiance atlas (--irradiance-atlas off) the merge writes none, and
// with --depth-tile 8 it coarsens the depth tiles after the filter, as the one-go bake does, in
// both gathers (the probe gather's bounce passes read the probes' full tiles).
TEST(ShardMerge, WithoutTheIrradianceAtlasAndWithCoarseDepthTiles) {
  const fs::path dir = fresh_dir("no_atlas");
  for (const std::string gather : {"path", "probes"})
    for (uint32_t n : {2u, 3u})
      expect_identity(
          dir, kCornell,
          std::string(kGrid) + " --irradiance-atlas off --depth-tile 8 --probe-filter on --gather " + gather, n);
  const CliResult info = run_gibake_cli("info " + shell_quote((dir / "merged.gibake").string()) + " --format json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(info.out.find("ddgi_irradiance"), std::string::npos) << info.out.substr(0, 2000);
  EXPECT_NE(info.out.find("ddgi_depth"), std::string::npos) << info.out.substr(0, 2000);
  EXPECT_NE(info.out.find("\"tile\": 8"), std::string::npos) << info.out.substr(0, 2000);
  fs::remove_all(dir);
}

// Every default (rays, --target-error 0.05, --max-rays 8 x rays, --ray-budget 1024, the default
// grid and its detail-volume rule, the surface fit) on the sample: the shards finished by the bake's
// own command are the one-go bake, no --ray-budget 0 needed. The fit reads the scene, so `gibake
// merge` refuses the parts, saying how to finish them, and writes nothing.
TEST(ShardMerge, DefaultBakeShards) {
  const fs::path dir = fresh_dir("default");
  for (uint32_t n : {2u, 5u}) expect_identity(dir, kCornell, "", n, "", Finish::FromShards);
  // The default bake refines where the lamp's light changes: a refined volume is sharded and merged too.
  const CliResult info = run_gibake_cli("info " + shell_quote((dir / "full.gibake").string()) + " --format json");
  EXPECT_NE(info.out.find("\"kind\": \"refined\""), std::string::npos) << info.out.substr(0, 2000);
  const std::string base = shell_quote(kCornell) + " --ddgi --progress lines";
  for (uint32_t i = 0; i < 2; ++i)
    ASSERT_EQ(run_gibake_cli(base + " --shard " + std::to_string(i) + "/2 --out " + part(dir, i)).exit_code, 0);
  const CliResult merged = run_gibake_cli("merge " + part(dir, 0) + " " + part(dir, 1) + " --out " +
                                          shell_quote((dir / "no.gibake").string()));
  EXPECT_EQ(merged.exit_code, 1) << merged.err;
  EXPECT_NE(merged.err.find("fits the atlases to the surfaces (--surface-fit on)"), std::string::npos) << merged.err;
  EXPECT_NE(merged.err.find("--from-shards"), std::string::npos) << merged.err;
  EXPECT_FALSE(fs::exists(dir / "no.gibake"));
  fs::remove_all(dir);
}

// Two volumes (the default grid and a --probe-volume, blocks numbered across both): the shards own
// blocks of either or both, and the merge writes both volumes as the one-go bake does, with the
// budget binding; 7 shards for 6 blocks.
TEST(ShardMerge, TwoVolumesAreByteIdenticalForAnyShardCount) {
  const fs::path dir = fresh_dir("volumes");
  const std::string volumes =
      "--probe-counts 16,16,5 --probe-volume -0.9,-0.4,-0.9:0.9,1.9,0.9:0.2 --rays 16 --target-error 0.02 "
      "--max-rays 256 --ray-budget 48";
  for (uint32_t n : {1u, 2u, 3u, 7u}) expect_identity(dir, kCornell, volumes, n);
  const CliResult info = run_gibake_cli("info " + shell_quote((dir / "full.gibake").string()) + " --format json");
  EXPECT_NE(info.out.find("\"probe_count\": 972"), std::string::npos) << "no second volume: " << info.out;
  expect_identity(dir, kCornell, volumes + " --gather probes", 3, "--threads 1");
  fs::remove_all(dir);
}

// The default grid and the detail volume its rule adds (the house on a ground plane: 19,602 and
// 5,720 probes, 51 blocks), the ray budget binding: shards own blocks of either volume or both.
TEST(ShardMerge, DetailVolumeOfTheRuleShards) {
  const fs::path dir = fresh_dir("detail");
  const std::string house = std::string(GIBAKE_SOURCE_DIR) + "/tests/volumes/house_on_ground.gltf";
  const std::string options = "--rays 16 --max-rays 256 --ray-budget 48 --reconstruction-check off --leak-audit off";
  for (uint32_t n : {2u, 5u}) expect_identity(dir, house, options, n);
  const CliResult info = run_gibake_cli("info " + shell_quote((dir / "full.gibake").string()) + " --format json");
  EXPECT_NE(info.out.find("\"probe_count\": 5720"), std::string::npos) << "no detail volume: " << info.out;
  fs::remove_all(dir);
}

// Shard 0 bakes the LPV; storage formats chosen at bake time are the merge's too.
TEST(ShardMerge, LpvAndStorageFormats) {
  const fs::path dir = fresh_dir("lpv");
  expect_identity(dir, kCornell, "--probe-counts 4,3,3 --rays 16 --lpv --lpv-res 8 --lpv-samples 2000", 3);
  expect_identity(dir, kCornell, "--probe-counts 4,3,3 --rays 16 --gather probes --sh-format f16 --atlas-format f32",
                  2);
  expect_identity(dir, kCornell, "--probe-counts 4,3,3 --rays 16 --atlas-format rgb9e5", 2);
  const CliResult info = run_gibake_cli("info " + shell_quote((dir / "full.gibake").string()));
  EXPECT_NE(info.out.find("rgb9e5"), std::string::npos) << info.out;
  fs::remove_all(dir);
}

// Refinement by check reads the scene and every probe: the shards' own command with --from-shards in
// place of --shard finishes the bake, the pass's volumes included, and writes the one-go bake's
// bytes. `gibake merge` refuses such parts, and a finishing command that differs from the shards'
// (another seed) is refused naming a part; neither writes anything.
TEST(ShardMerge, RefinementByCheckFinishesFromTheShards) {
  const fs::path dir = fresh_dir("checked");
  // The rule's refined volumes (a ray budget of their own) and the pass's after them.
  const std::string checked =
      "--rays 64 --refine-budget 1024 --refine-by-check 4096 --check-patches 8 --check-rays 32 --leak-audit off";
  for (uint32_t n : {2u, 3u}) expect_identity(dir, kCornell, checked, n, "", Finish::FromShards);
  const CliResult info = run_gibake_cli("info " + shell_quote((dir / "full.gibake").string()) + " --format json");
  EXPECT_NE(info.out.find("where the bake's check missed"), std::string::npos)
      << "the pass placed nothing: " << info.out;

  const std::string base = shell_quote(kCornell) + " --ddgi " + checked + " --progress lines";
  for (uint32_t i = 0; i < 2; ++i)
    ASSERT_EQ(run_gibake_cli(base + " --shard " + std::to_string(i) + "/2 --out " + part(dir, i)).exit_code, 0);
  const std::string parts = part(dir, 0) + " " + part(dir, 1), out = shell_quote((dir / "no.gibake").string());
  const CliResult merged = run_gibake_cli("merge " + parts + " --out " + out);
  EXPECT_EQ(merged.exit_code, 1) << merged.err;
  EXPECT_NE(merged.err.find("refines by check (--refine-by-check 4096)"), std::string::npos) << merged.err;
  const CliResult other = run_gibake_cli(base + " --seed 9 --from-shards " + parts + " --out " + out);
  EXPECT_EQ(other.exit_code, 3) << other.err;
  EXPECT_NE(other.err.find(part(dir, 0) + ": input hash: "), std::string::npos) << other.err;
  EXPECT_FALSE(fs::exists(dir / "no.gibake"));
  fs::remove_all(dir);
}

bool have_lavapipe() {
  const CliResult r = run_gibake_cli("info --devices");
  return r.exit_code == 0 && r.out.find("llvmpipe") != std::string::npos;
}

// On the Vulkan backend too: the path kernel per probe, and the probe gather's bounce passes run by
// the merge on the device the shards name. 576 probes (the sample's default 8 x 8 x 9) of 8 rays a
// batch: blocks of 512 and 64, one a shard; the shard counts and their empty shards are the CPU tests' above.
TEST(ShardMerge, LavapipeBothGathers) {
  if (!have_lavapipe()) GTEST_SKIP() << "no lavapipe device";
  const fs::path dir = fresh_dir("vulkan");
  const std::string vk = " --backend vulkan --vulkan-device lavapipe";
  const std::string grid = "--probe-counts 8,8,9 --rays 8";
  expect_identity(dir, kCornell, grid + " --bounces 2" + vk, 2);
  expect_identity(dir, kCornell, grid + " --bounces 2 --gather probes" + vk, 2);
  expect_identity(dir, kCornell, grid + " --target-error 0.02 --max-rays 128 --ray-budget 32" + vk, 2);
  fs::remove_all(dir);
}

class ShardMergeBadParts : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_dir("bad");
    const std::string base =
        shell_quote(kCornell) + " --ddgi --surface-fit off --probe-counts 16,16,5 --rays 8 --progress lines";
    for (uint32_t i = 0; i < 3; ++i)
      ASSERT_EQ(run_gibake_cli(base + " --shard " + std::to_string(i) + "/3 --out " + part(dir_, i)).exit_code, 0);
    auto p = [](const std::string& name) { return (dir_ / name).string(); };
    ASSERT_EQ(run_gibake_cli(base + " --seed 5 --shard 1/3 --out " + p("seed.gibake")).exit_code, 0);
    ASSERT_EQ(run_gibake_cli(shell_quote(kBlocks) +
                             " --ddgi --surface-fit off --probe-counts 16,16,5 --rays 8 --shard 1/3 --out " +
                             p("scene.gibake"))
                  .exit_code,
              0);
    ASSERT_EQ(run_gibake_cli(base + " --shard 1/2 --out " + p("of2.gibake")).exit_code, 0);
    const std::string other_path = std::string(GIBAKE_SOURCE_DIR) + "/samples/../samples/cornell/cornell.gltf";
    ASSERT_EQ(run_gibake_cli(shell_quote(other_path) +
                             " --ddgi --surface-fit off --probe-counts 16,16,5 --rays 8 --shard 1/3 --out " +
                             p("path.gibake"))
                  .exit_code,
              0);
    ASSERT_EQ(run_gibake_cli(base + " --out " + p("whole.gibake")).exit_code, 0);
    std::string bytes = bytes_of(part(dir_, 1));
    std::string flipped = bytes;
    flipped[bytes.size() / 2] ^= 0x40;
    std::ofstream(p("corrupt.gibake"), std::ios::binary) << flipped;
    std::ofstream(p("truncated.gibake"), std::ios::binary) << bytes.substr(0, bytes.size() / 3);
    // Whole and checksummed, but one value is no number (a shard made wrong, not damaged on disk).
    std::vector<gibake::DdgiShard> volumes;
    ASSERT_TRUE(gibake::read_shard_volumes(part(dir_, 1), volumes, nullptr).is_ok());
    volumes[0].sh0[0] = std::numeric_limits<float>::quiet_NaN();
    ASSERT_TRUE(gibake::write_shard_file(p("nan.gibake"), volumes, nullptr, gibake::BakeFileOptions{}, {}).is_ok());
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // Merging `parts` fails with exit 3, one error line naming `culprit`, and writes nothing.
  static void expect_refused(const std::string& parts, const std::string& culprit, int code = 3) {
    SCOPED_TRACE(parts);
    const fs::path out = dir_ / "merged.gibake";
    const CliResult r = run_gibake_cli("merge " + parts + " --out " + out.string());
    EXPECT_EQ(r.exit_code, code);
    const std::vector<std::string> lines = gibake::test::split_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("gibake: error: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find(culprit), std::string::npos) << lines[0];
    EXPECT_FALSE(fs::exists(out));
  }
  static std::string p(const std::string& name) { return (dir_ / name).string(); }
  static fs::path dir_;
};
fs::path ShardMergeBadParts::dir_;

TEST_F(ShardMergeBadParts, MissingDuplicateForeignCorrupt) {
  const std::string p0 = part(dir_, 0), p1 = part(dir_, 1), p2 = part(dir_, 2);
  expect_refused(p0 + " " + p2, "shard 1 of 3");                          // missing
  expect_refused(p0 + " " + p1 + " " + p2 + " " + p1, "given twice");     // duplicated
  expect_refused(p0 + " " + p("seed.gibake") + " " + p2, "seed.gibake");  // other settings
  expect_refused(p0 + " " + p("scene.gibake") + " " + p2, "scene.gibake");  // other scene
  expect_refused(p0 + " " + p("of2.gibake") + " " + p2, "of2.gibake");      // other shard count
  expect_refused(p0 + " " + p("path.gibake") + " " + p2, "path.gibake");    // scene given by another path
  expect_refused(p0 + " " + p("corrupt.gibake") + " " + p2, "corrupt.gibake");
  expect_refused(p0 + " " + p("truncated.gibake") + " " + p2, "truncated.gibake");
  expect_refused(p0 + " " + p("nan.gibake") + " " + p2, "nan.gibake: volume 0 sh: 1 NaN or infinite values");
  expect_refused(p0 + " " + p("whole.gibake") + " " + p2, "not a shard file");
  expect_refused(p0 + " " + p("absent.gibake") + " " + p2, "absent.gibake", 2);
  // The complete set merges; never over one of its parts.
  EXPECT_EQ(run_gibake_cli("merge " + p2 + " " + p0 + " " + p1 + " --out " + p("ok.gibake")).exit_code, 0);
  const std::string before = bytes_of(p1);
  EXPECT_NE(run_gibake_cli("merge " + p0 + " " + p1 + " " + p2 + " --out " + p1).exit_code, 0);
  EXPECT_EQ(bytes_of(p1), before);
}

TEST_F(ShardMergeBadParts, InfoAndVerifyUnderstandShards) {
  CliResult r = run_gibake_cli("info " + part(dir_, 1) + " --format json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"shard\""), std::string::npos);
  EXPECT_NE(r.out.find("\"probe_begin\": 512"), std::string::npos) << r.out;
  r = run_gibake_cli("info " + part(dir_, 1));
  EXPECT_NE(r.out.find("shard 1 of 3"), std::string::npos) << r.out;
  r = run_gibake_cli("verify " + part(dir_, 1) + " --scene " + shell_quote(kCornell));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("pass  shard: shard 1 of 3"), std::string::npos) << r.out;
  EXPECT_EQ(run_gibake_cli("verify " + p("corrupt.gibake")).exit_code, 3);
}

TEST(ShardMergeArgs, BadShardArguments) {
  const std::string base = shell_quote(kCornell) + " --ddgi --out /tmp/gibake_shard_args.gibake --shard ";
  for (const char* bad : {"3/3", "1/0", "-1/2", "a/b", "1", "1/2/3", "0/70000"})
    EXPECT_EQ(run_gibake_cli(base + bad).exit_code, 1) << bad;
  EXPECT_EQ(run_gibake_cli(base + "0/2 --report /tmp/r.html").exit_code, 1);
  EXPECT_EQ(run_gibake_cli(base + "0/2 --metadata-timings").exit_code, 1);
  EXPECT_EQ(run_gibake_cli(shell_quote(kCornell) + " --lpv --out /tmp/x.gibake --shard 0/2").exit_code, 1);
  EXPECT_EQ(run_gibake_cli("merge --out /tmp/x.gibake").exit_code, 1);
  EXPECT_FALSE(fs::exists("/tmp/gibake_shard_args.gibake"));
}

}  // namespace
