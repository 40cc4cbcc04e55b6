// Several DDGI volumes from the command line (bake/ddgi/volumes.h), on the house standing on a ground
// plane 20 times its size (tests/volumes/make_house.py): the default bake adds a detail volume around
// the house (read back through the runtime loader), the picture inside the house is clearly closer to
// the path-traced truth with it than with the single default grid, --probe-volume adds boxes at their
// spacing exactly, --default-volume off keeps only those, and bad requests fail in one line (exit 1).
// The bakes run within --probe-budget 3000 at 64 rays so the test stays a few seconds; the rule
// compares spacings, so it fires at the default budget too (bake_probe_volumes_test).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

#include "gibake/loader.hpp"
#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

using namespace gibake::test;

const std::string kHouse = std::string(GIBAKE_SOURCE_DIR) + "/tests/volumes/house_on_ground.gltf";
// Inside the left room, looking past the sunlit floor patch at the inner wall and its door.
const std::string kInside = "--camera -3.5,1.6,2.5,-0.5,0.8,-2.5,0,1,0 --fov 75";

struct Blocks {
  bool found = false;
  double within = 0.0, median = 0.0, p90 = 0.0;
};

// "8x8 blocks: <within>% of N within 10% ...; lit/reference p10 a, median b, p90 c".
Blocks parse_blocks(const std::string& text) {
  Blocks b;
  static const std::regex line(R"(8x8 blocks: ([0-9.]+)% .*median ([0-9.]+), p90 ([0-9.]+))");
  std::smatch m;
  if (!std::regex_search(text, m, line)) return b;
  b.found = true;
  b.within = std::stod(m[1]) / 100.0;
  b.median = std::stod(m[2]);
  b.p90 = std::stod(m[3]);
  return b;
}

std::string read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class ProbeVolumes : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return shell_quote(scratch_.path(name)); }
  // Small and fast: 64 rays a batch up to 1,024 (the default cap, 8 x --rays, would stop at 512 and
  // leave the rooms' picture at 52.6% instead of 65.6% of blocks within 10%).
  CliResult bake(const std::string& out, const std::string& extra) const {
    return run_gibake_cli(shell_quote(kHouse) + " --ddgi --out " + path(out) +
                          " --probe-budget 3000 --rays 64 --max-rays 1024 --reconstruction-check off " + extra);
  }
  gibake::loader::BakeFile open(const std::string& name) const {
    gibake::loader::BakeFile f;
    EXPECT_FALSE(f.open(scratch_.path(name))) << name;
    return f;
  }
  Blocks picture(const std::string& bake_name, const std::string& extra = "") const {
    const CliResult view = run_gibake_cli("preview " + shell_quote(kHouse) + " --bake " + path(bake_name) + " " + extra + " " +
                                          kInside + " --size 128x96 --spp 128 --diff " + path("diff.png") +
                                          " --out " + path("lit.png"));
    EXPECT_EQ(view.exit_code, 0) << view.err;
    const Blocks b = parse_blocks(view.out + view.err);
    EXPECT_TRUE(b.found) << view.out << view.err;
    return b;
  }
  ScratchDir scratch_{"probe_volumes"};
};

TEST_F(ProbeVolumes, TheDefaultBakeAddsADetailVolumeAroundTheHouseAndThePictureInsideIsBetter) {
  const CliResult with = bake("with.gibake", "");
  ASSERT_EQ(with.exit_code, 0) << with.err;
  EXPECT_NE(with.err.find("volume 1 (detail)"), std::string::npos) << with.err;
  EXPECT_NE(with.err.find("detail-volume rule:"), std::string::npos) << with.err;
  // The detail volume's stages carry its name and the words volume 0's have.
  const size_t seconds = with.err.find("  seconds:");
  ASSERT_NE(seconds, std::string::npos) << with.err;
  const std::string line = with.err.substr(seconds, with.err.find('\n', seconds) - seconds);
  EXPECT_NE(line.find(", volume 1 ray tracing "), std::string::npos) << line;
  EXPECT_NE(line.find(", volume 1 probe relocation "), std::string::npos) << line;
  EXPECT_EQ(line.find("volume 1 trace"), std::string::npos) << line;
  EXPECT_EQ(line.find("task beside"), std::string::npos) << line;
  const gibake::loader::BakeFile file = open("with.gibake");
  ASSERT_EQ(file.ddgi_volumes().size(), 2u);
  const gibake_ddgi_volume& coarse = file.ddgi_volumes()[0].desc();
  const gibake_ddgi_volume& detail = file.ddgi_volumes()[1].desc();
  EXPECT_LE(uint64_t(coarse.probe_count) + detail.probe_count, 3000u);  // one budget for both
  // The detail volume spans the house (x -4..4, y 0..3.2, z -3..3) within a cell and a voxel.
  const float lo[3] = {-4.f, 0.f, -3.f}, hi[3] = {4.f, 3.2f, 3.f};
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(detail.grid_min[a], lo[a] + 0.5f) << a;
    EXPECT_GT(detail.grid_max[a], hi[a] - 0.5f) << a;
    EXPECT_GT(detail.grid_min[a], lo[a] - 2.5f) << a;
    EXPECT_LT(detail.grid_max[a], hi[a] + 2.5f) << a;
    EXPECT_LT(detail.spacing[a], 0.8f) << a;
  }
  EXPECT_GT(coarse.spacing[0], 4.f * detail.spacing[0]);

  const CliResult single = bake("single.gibake", "--detail-volumes off");
  ASSERT_EQ(single.exit_code, 0) << single.err;
  ASSERT_EQ(open("single.gibake").ddgi_volumes().size(), 1u);
  // Both volumes blended as an engine blends them (docs/FORMAT.md "Several volumes"): every surface
  // in view lies at the detail volume's full weight (the house, with its fade band to spare).
  const Blocks b_with = picture("with.gibake"), b_single = picture("single.gibake");
  std::printf("inside the house: detail volume %.1f%% of blocks within 10%% (median %.3f, p90 %.3f); single grid "
              "%.1f%% (median %.3f, p90 %.3f)\n",
              100 * b_with.within, b_with.median, b_with.p90, 100 * b_single.within, b_single.median, b_single.p90);
  // 87.0% with the default fit's paths (--fit-gather both), 81.8% with whole paths alone, 24.0% with
  // paths ended in the probes' light alone (the sun's probes outside lead them): the default's
  // blend must fall back to the whole paths where the probes are wrong.
  EXPECT_GE(b_with.within, 0.8);
  EXPECT_GE(b_with.within, b_single.within + 0.3);
  EXPECT_NEAR(b_with.median, 1.0, 0.1);
  // The coarse grid's probes outside, in the sun, light the rooms (the sampler's fade behind the
  // walls keeps some of them out, and the fit corrects some of the rest: not enough).
  EXPECT_LE(b_single.within, 0.55);
  EXPECT_GE(b_single.p90, 1.5);

  // verify --against covers every volume: a file against itself passes, the one-grid file fails.
  EXPECT_EQ(run_gibake_cli("verify " + path("with.gibake") + " --against " + path("with.gibake")).exit_code, 0);
  const CliResult differ = run_gibake_cli("verify " + path("with.gibake") + " --against " + path("single.gibake"));
  EXPECT_NE(differ.exit_code, 0);
  EXPECT_NE((differ.out + differ.err).find("number of DDGI volumes"), std::string::npos) << differ.out << differ.err;
  const CliResult info = run_gibake_cli("info " + path("with.gibake"));
  EXPECT_NE(info.out.find("ddgi volume 1:"), std::string::npos) << info.out;
  // The file's metadata says why each volume exists.
  const CliResult json = run_gibake_cli("info " + path("with.gibake") + " --format json");
  EXPECT_NE(json.out.find(R"("kind": "detail")"), std::string::npos) << json.out.substr(0, 2000);
  EXPECT_NE(json.out.find("detail volume added"), std::string::npos);
}

TEST_F(ProbeVolumes, GivenVolumesKeepTheirSpacingAndMayStandAlone) {
  const CliResult three = bake("three.gibake", "--probe-volume -2,0.5,-2:2,2.5,2:0.5");
  ASSERT_EQ(three.exit_code, 0) << three.err;
  const gibake::loader::BakeFile file = open("three.gibake");
  ASSERT_EQ(file.ddgi_volumes().size(), 3u);  // default, detail, given
  const gibake_ddgi_volume& given = file.ddgi_volumes()[2].desc();
  // 4 m / 0.5 m = 8 cells along x and z, 2 m / 0.5 m = 4 along y, a probe at each cell's centre.
  EXPECT_EQ(given.counts[0], 8);
  EXPECT_EQ(given.counts[1], 4);
  EXPECT_EQ(given.counts[2], 8);
  EXPECT_NEAR(given.spacing[0], 0.5f, 1e-5f);
  EXPECT_FLOAT_EQ(given.grid_min[0], -1.75f);
  EXPECT_FLOAT_EQ(given.grid_min[1], 0.75f);

  const CliResult alone = bake("alone.gibake", "--default-volume off --probe-volume -4,0,-3:4,3.2,3");
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  const gibake::loader::BakeFile one = open("alone.gibake");
  ASSERT_EQ(one.ddgi_volumes().size(), 1u);
  // Without the default grid the given volume takes the rule within the whole budget: 8 / 24 m
  // gives 24 x 10 x 18 = 4,320 probes, so it widens in 5% steps until 3,000 fit: 8 / 24 x 1.05^4.
  EXPECT_NEAR(one.ddgi_volumes()[0].desc().spacing[0], 8.f / 24.f * 1.05f * 1.05f * 1.05f * 1.05f, 1e-4f);
}

// A near volume (--probe-volume ...:near) traces only the probes with a surface within 2.5 spacings:
// the others get no rays and are Inactive, and a surface point, which reads only the corners of its
// own cell, is lit exactly as by the same volume with every probe traced (fixed rays, no fit: each
// probe's light is then its own rays' alone).
TEST_F(ProbeVolumes, ANearVolumeTracesOnlyTheProbesSurfacesReadAndLightsThemAlike) {
  const std::string box = "--surface-fit off --target-error 0 --probe-volume=-4,0.05,-3:4,6.05,3:0.25";
  const CliResult full = bake("full.gibake", box);
  ASSERT_EQ(full.exit_code, 0) << full.err;
  const CliResult near = bake("near.gibake", box + ":near");
  ASSERT_EQ(near.exit_code, 0) << near.err;
  EXPECT_NE((near.out + near.err).find("left out (no surface within 0.625 m)"), std::string::npos) << near.err;
  const gibake::loader::BakeFile a = open("full.gibake"), b = open("near.gibake");
  ASSERT_EQ(a.ddgi_volumes().size(), 3u);
  ASSERT_EQ(b.ddgi_volumes().size(), 3u);
  const gibake::loader::DdgiVolume &va = a.ddgi_volumes()[2], &vb = b.ddgi_volumes()[2];
  ASSERT_EQ(va.desc().probe_count, vb.desc().probe_count);
  uint32_t left_out = 0, high_left_out = 0, high = 0;
  for (uint32_t p = 0; p < vb.desc().probe_count; ++p) {
    const bool out = vb.state(p) == GIBAKE_PROBE_INACTIVE && vb.stats(p).rays == 0;
    left_out += out;
    EXPECT_GT(va.stats(p).rays, 0u) << p;  // the full volume traced every probe
    if (!out) {
      EXPECT_EQ(va.stats(p).rays, vb.stats(p).rays) << p;
    }
    // Layers above the roof (3.2 m) by more than the reach: nothing is near them.
    const float y = vb.desc().grid_min[1] +
                    float(p / uint32_t(vb.desc().counts[0]) % uint32_t(vb.desc().counts[1])) * vb.desc().spacing[1];
    if (y > 3.2f + 0.625f + 0.01f) high_left_out += out, ++high;
  }
  EXPECT_GT(high, 0u);
  EXPECT_EQ(high_left_out, high);                  // every probe far above the house
  EXPECT_GT(left_out, vb.desc().probe_count / 4);  // a quarter at least: the box's upper half
  EXPECT_LT(left_out, vb.desc().probe_count);      // and not those near the ground and the house
  // The file keeps only the probes a sampler reads (a sparse volume, format 1.5).
  EXPECT_TRUE(vb.sparse());
  EXPECT_FALSE(va.sparse());
  uint32_t readable = 0;
  for (uint32_t p = 0; p < vb.desc().probe_count; ++p) readable += vb.state(p) != GIBAKE_PROBE_INACTIVE;
  EXPECT_EQ(vb.stored_probes(), readable);
  EXPECT_LT(std::filesystem::file_size(scratch_.path("near.gibake")),
            std::filesystem::file_size(scratch_.path("full.gibake")) * 3 / 4);
  // The ground and the house's floors as the sampler reads them, both bakes alike within 5e-3
  // relative: the same probes and texels, but the sampler computes its bilinear weights in atlas
  // coordinates, which round with each tile's place in its atlas (2^-10 texel at 16384 texels), and
  // the Chebyshev weight's cube passes that on where depth changes fast across a tile.
  int compared = 0;
  float worst = 0.f;
  for (float x = -3.9f; x <= 3.9f; x += 0.37f)
    for (float z = -2.9f; z <= 2.9f; z += 0.41f) {
      const gibake::loader::Vec3 p{x, 0.001f, z}, n{0.f, 1.f, 0.f};
      gibake::loader::Rgb ea{}, eb{};
      ASSERT_TRUE(a.sample_ddgi(p, n, ea));
      ASSERT_TRUE(b.sample_ddgi(p, n, eb));
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(ea[size_t(k)], eb[size_t(k)], 5e-3f * ea[size_t(k)]) << x << "," << z;
        worst = std::max(worst, std::fabs(ea[size_t(k)] - eb[size_t(k)]) / ea[size_t(k)]);
      }
      ++compared;
    }
  EXPECT_GT(compared, 300);
  std::printf("near volume against the full one: %d points, largest relative difference %.3g\n", compared,
              double(worst));
  // A near volume with nothing near: said in one warning, not taken for a black bake.
  const CliResult sky = bake("sky.gibake", "--surface-fit off --probe-volume=-4,20,-3:4,25,3:0.5:near");
  ASSERT_EQ(sky.exit_code, 0) << sky.err;
  EXPECT_NE(sky.err.find("warning: a near volume (--probe-volume ...:near) has no surface within 1.25 m of any of its "
                         "1920 probes: none traced, it lights nothing"),
            std::string::npos)
      << sky.err;
  EXPECT_EQ(sky.err.find("black everywhere"), std::string::npos) << sky.err;
}

TEST_F(ProbeVolumes, BadRequestsFailInOneLine) {
  for (const char* args :
       {"--probe-volume 1,2,3", "--probe-volume 1,2,3:0,5,6", "--probe-volume 0,0,0:1,1,1:-2",
        "--probe-volume 0,0,0:1,1,1:", "--probe-volume 0,0,0:1,1,1:0.5:far", "--probe-volume 0,0,0:1,1,1:near:0.5",
        "--default-volume off", "--detail-volumes maybe", "--surface-fit off --from-shards part.gibake",
        "--refine-by-check 100 --shard 0/2 --from-shards part.gibake"}) {
    const CliResult r = bake("bad.gibake", args);
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.err;
    const size_t error = r.err.find("gibake: error: ");
    ASSERT_NE(error, std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(r.err.find('\n', error), r.err.size() - 1) << args << ": " << r.err;  // one line, the last
  }
}

// --near-camera: a view volume over the surfaces the view sees, a quarter of the finest spacing
// there (the detail volume's), its probes near surfaces only and stored sparse; the picture from
// that view is clearly closer to the path-traced truth (fixed 64 rays a probe, no fit, so that the
// test stays a few seconds: 34.9% of blocks within 10% without it, 51.0% with it when the test
// came). Malformed views are refused in one line before anything is written.
TEST_F(ProbeVolumes, ANearCameraAddsAViewVolumeWhereItLooksAndItsPictureIsCloser) {
  const std::string fixed = "--surface-fit off --target-error 0";
  const std::string camera = "-3.5,1.6,2.5,-0.5,0.8,-2.5,0,1,0";
  ASSERT_EQ(bake("plain.gibake", fixed).exit_code, 0);
  const CliResult r = bake("view.gibake", fixed + " --near-camera " + camera + " --near-fov 75");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE((r.out + r.err).find("(view): "), std::string::npos) << r.out << r.err;
  EXPECT_NE((r.out + r.err).find("the surfaces --near-camera " + camera + " sees (57600 of 57600 rays hit)"),
            std::string::npos)
      << r.out;
  const gibake::loader::BakeFile plain = open("plain.gibake"), view = open("view.gibake");
  ASSERT_EQ(view.ddgi_volumes().size(), plain.ddgi_volumes().size() + 1);
  const gibake::loader::DdgiVolume& v = view.ddgi_volumes()[2];  // the default grid, the detail volume, the view's
  const gibake::loader::DdgiVolume& detail = view.ddgi_volumes()[1];
  EXPECT_TRUE(v.sparse());
  EXPECT_LT(v.stored_probes(), v.desc().probe_count);
  EXPECT_FLOAT_EQ(v.desc().spacing[0], detail.desc().spacing[0] / 4.f);
  for (int a = 0; a < 3; ++a) {  // the camera looks from inside the house: its box holds the eye
    const float eye = a == 0 ? -3.5f : a == 1 ? 1.6f : 2.5f;
    EXPECT_LT(v.desc().grid_min[a], eye) << a;
    EXPECT_GT(v.desc().grid_max[a], eye) << a;
  }
  EXPECT_NE(view.metadata_json().find("\"kind\":\"view\""), std::string::npos);
  const Blocks without = picture("plain.gibake"), with = picture("view.gibake");
  EXPECT_GT(with.within, without.within + 0.08) << without.within << " -> " << with.within;
  std::printf("the view's picture: %.1f%% of blocks within 10%% without its volume, %.1f%% with it\n",
              100.0 * without.within, 100.0 * with.within);

  // --near-spacing replaces the rule's spacing (here half the detail volume's).
  const float half = detail.desc().spacing[0] / 2.f;
  const CliResult spaced = bake(
      "spaced.gibake", fixed + " --near-camera " + camera + " --near-fov 75 --near-spacing " + std::to_string(half));
  ASSERT_EQ(spaced.exit_code, 0) << spaced.err;
  EXPECT_NE((spaced.out + spaced.err).find("(--near-spacing; the finest volume there is"), std::string::npos)
      << spaced.out;
  const gibake::loader::BakeFile coarser = open("spaced.gibake");
  ASSERT_EQ(coarser.ddgi_volumes().size(), view.ddgi_volumes().size());
  EXPECT_NEAR(coarser.ddgi_volumes()[2].desc().spacing[0], half, 1e-3f * half);
  EXPECT_NE(coarser.metadata_json().find("\"near_spacing\""), std::string::npos);

  const std::pair<const char*, const char*> bad_args[] = {
      {"--near-camera gltf:x", "--near-camera"},
      {"--near-camera gltf:3", "--near-camera"},
      {"--near-camera default --near-fov 200", "--near-fov"},
      {"--near-spacing 0.2", "--near-spacing"},
      {"--near-camera default --near-spacing 0.001", "--near-spacing"},
      {"--near-camera default --near-spacing nan", "--near-spacing"}};
  for (const auto& [args, option] : bad_args) {
    const CliResult b = bake("bad.gibake", args);
    EXPECT_EQ(b.exit_code, 1) << args << ": " << b.err;
    EXPECT_NE(b.err.find(option), std::string::npos) << b.err;
    EXPECT_FALSE(std::filesystem::exists(scratch_.path("bad.gibake"))) << args;
  }
}

// Refinement by the bake's check on the bundled sample (small: 128 patches of 32 paths a point):
// the pass's line and refined volumes, the same bytes for 1 and 2 threads, and a file that
// `verify` passes and the loader reads with every volume.
TEST_F(ProbeVolumes, RefinementByCheckIsTheSameForAnyThreadCountAndVerifies) {
  const std::string sample = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  std::string bytes[2];
  for (int threads = 1; threads <= 2; ++threads) {
    const std::string name = "checked" + std::to_string(threads) + ".gibake";
    const CliResult r = run_gibake_cli(shell_quote(sample) +
                                       " --ddgi --rays 64 --refine-budget 0 --refine-by-check 4096"
                                       " --check-patches 8 --check-rays 32 --threads " +
                                       std::to_string(threads) + " --out " + path(name));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("refinement by check: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("where the bake's check missed"), std::string::npos) << r.err;
    bytes[threads - 1] = read_file_bytes(scratch_.path(name));
  }
  EXPECT_FALSE(bytes[0].empty());
  EXPECT_EQ(bytes[0], bytes[1]);
  const gibake::loader::BakeFile file = open("checked1.gibake");
  EXPECT_GT(file.ddgi_volumes().size(), 1u);
  const CliResult v = run_gibake_cli("verify " + path("checked1.gibake"));
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
}

}  // namespace
