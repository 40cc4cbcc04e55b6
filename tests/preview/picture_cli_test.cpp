// The picture at image level, the fast version CI keeps: a default bake of a scene, rendered the
// way an engine lights it (`preview --mode lit`: the loader's sampler plus punctual lights, each
// pixel's area integrated as the reference integrates it), against the converged path tracer's
// reference of the same view (`--diff`, 8x8-pixel blocks of luminance; the reference itself is
// held to Blender Cycles by tests/reference/picture_reference_test.cpp), and the bake's own
// reconstruction check from that camera (`--check-patches`). The reference is generated here at
// 512 samples a pixel, the check's at 512 paths a point, so their own noise stays well under the
// 10% the blocks are judged by. Every figure is deterministic (fixed seeds, any thread count), so
// each floor sits just under its measured figure (docs/BENCHMARKS.md "The picture") and catches
// any regression. The goal, 80% of blocks within 10%, is met by the sample and two_rooms (with the
// default refined volumes where the light changes); cornell-box-nvpro meets it against a 4,096-spp
// reference (docs/BENCHMARKS.md "The fit's gather") and falls a little short here, at this size
// and these samples: its walls of albedo 1 keep most of the light in long roulette paths, whose
// noise the fit's paths ended in the probes' light (--fit-gather both) keep out of the fit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ostream>
#include <regex>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

using namespace gibake::test;  // run_gibake_cli, shell_quote, ScratchDir

// "within 10%" share and the p90 of baked / reference, as one measure prints them.
struct Measure {
  bool found = false;
  double within = 0.0, p10 = 0.0, median = 0.0, p90 = 0.0;
};

// Reads the line that starts with `head` ("8x8 blocks:" or "reconstruction error (camera"):
// "<within>% ... p10 <a>, median <b>, p90 <c>".
Measure parse_measure(const std::string& text, const std::string& head) {
  Measure m;
  const size_t at = text.find(head);
  if (at == std::string::npos) return m;
  const std::string line = text.substr(at, text.find('\n', at) - at);
  static const std::regex within(R"(([0-9.]+)% (of [0-9]+ )?within 10%)");
  static const std::regex quantiles(R"(p10 ([0-9.]+), median ([0-9.]+), p90 ([0-9.]+))");
  std::smatch w, q;
  if (!std::regex_search(line, w, within) || !std::regex_search(line, q, quantiles)) return m;
  m.found = true;
  m.within = std::stod(w[1]) / 100.0;
  m.p10 = std::stod(q[1]);
  m.median = std::stod(q[2]);
  m.p90 = std::stod(q[3]);
  return m;
}

struct View {
  const char* name;
  std::string scene;
  std::string camera;  // preview options choosing the view ("" = the default camera)
  double min_within;   // floor on the share of blocks within 10%
  double max_p90;      // ceiling on the p90 of the block ratio
};

void PrintTo(const View& v, std::ostream* os) { *os << v.name; }

class Picture : public ::testing::TestWithParam<View> {
 protected:
  std::string path(const std::string& name) const { return shell_quote(scratch_.path(name)); }
  ScratchDir scratch_{"picture"};
};

TEST_P(Picture, DefaultBakeLooksLikeThePathTracedTruth) {
  const View& v = GetParam();
  const CliResult bake = run_gibake_cli(shell_quote(v.scene) + " --ddgi --out " + path("b.gibake"));
  ASSERT_EQ(bake.exit_code, 0) << bake.err;
  const CliResult view =
      run_gibake_cli("preview " + shell_quote(v.scene) + " --bake " + path("b.gibake") + " " + v.camera +
                     " --size 128x96 --spp 512 --diff " + path("diff.png") + " --check-patches 96 --check-rays 512 --out " +
                     path("lit.png"));
  ASSERT_EQ(view.exit_code, 0) << view.err;
  const Measure image = parse_measure(view.out + view.err, "8x8 blocks:");
  const Measure check = parse_measure(view.out + view.err, "reconstruction error (camera");
  ASSERT_TRUE(image.found) << view.out << view.err;
  ASSERT_TRUE(check.found) << view.out << view.err;
  std::printf("%s: blocks %.1f%% within 10%%, p10 %.3f median %.3f p90 %.3f; check %.0f%%, p90 %.2f\n", v.name,
              100 * image.within, image.p10, image.median, image.p90, 100 * check.within, check.p90);
  EXPECT_GE(image.within, v.min_within);
  EXPECT_LE(image.p90, v.max_p90);
  EXPECT_NEAR(image.median, 1.0, 0.06);  // no overall bias
  // The bake's own check tells the user what the image shows: its share of patches off by more than
  // 10% within a factor of 1.5 of the blocks' (the agreement bound between the check and the
  // image), once either share is large enough to measure on this many blocks.
  // A patch's reference has noise of its own (relative standard error s, the check's "reference
  // noise"): a bake equal to the truth would still read a share 1 - erf(0.1 / (s sqrt 2)) of the
  // patches off by more than 10%, which the check's share may hold on top. Likewise the image's
  // reference (its blocks' share within 10% of the truth, from its two halves) for the image's.
  std::smatch noise;
  const std::string text = view.out + view.err;
  ASSERT_TRUE(std::regex_search(text, noise, std::regex(R"(reference noise ([0-9.]+)%( \([^)]*\))?; [0-9.]+ s)")))
      << text;
  const double s = std::stod(noise[1]) / 100.0;
  const double noise_off = s > 0.0 ? 1.0 - std::erf(0.1 / (s * std::sqrt(2.0))) : 0.0;
  std::smatch image_noise;
  ASSERT_TRUE(
      std::regex_search(text, image_noise, std::regex(R"(within 10% of the truth on about ([0-9.]+)% of these)")))
      << text;
  const double image_noise_off = 1.0 - std::stod(image_noise[1]) / 100.0;
  const double off_image = 1.0 - image.within, off_check = 1.0 - check.within;
  std::printf(
      "%s: the check's reference noise %.1f%% alone puts %.0f%% of its patches off, the image's %.0f%% of its blocks\n",
      v.name, 100 * s, 100 * noise_off, 100 * image_noise_off);
  if (off_image > 0.1 || off_check > 0.1) {
    EXPECT_LE(off_check, 1.5 * off_image + noise_off);
    EXPECT_LE(off_image, 1.5 * off_check + image_noise_off);
  }
}

// two_rooms' sunlit room baked with `args`, from inside it, against its converged reference: the
// blocks' measure and the relative RMS. Every call shares the reference's seed, so its noise (256
// samples) moves every bake alike. `bake_err`: what the bake printed.
struct RoomPicture {
  Measure blocks;
  double rms = 0.0;
  std::string bake_err;
};
RoomPicture room_picture(const ScratchDir& scratch, const std::string& name, const std::string& args) {
  RoomPicture out;
  const std::string scene = std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/two_rooms.gltf";
  const std::string bake = shell_quote(scratch.path(name + ".gibake"));
  const CliResult b = run_gibake_cli(shell_quote(scene) + " --ddgi " + args + " --out " + bake);
  EXPECT_EQ(b.exit_code, 0) << b.err;
  out.bake_err = b.err;
  const CliResult view = run_gibake_cli("preview " + shell_quote(scene) + " --bake " + bake +
                                        " --camera -1.9,1.2,0.9,-0.3,0.7,-0.9,0,1,0 --fov 75 --size 128x96 --spp 256"
                                        " --diff " +
                                        shell_quote(scratch.path(name + ".diff.png")) + " --out " +
                                        shell_quote(scratch.path(name + ".png")));
  EXPECT_EQ(view.exit_code, 0) << view.err;
  const std::string text = view.out + view.err;
  out.blocks = parse_measure(text, "8x8 blocks:");
  EXPECT_TRUE(out.blocks.found) << text;
  std::smatch r;
  EXPECT_TRUE(std::regex_search(text, r, std::regex(R"(relative RMS ([0-9.]+))"))) << text;
  if (!r.empty()) out.rms = std::stod(r[1]);
  return out;
}

// Refinement (bake/ddgi/refine.h) against the same truth: two_rooms' sunlit room with the default
// refined volumes and with --refine-budget 0, the same view and reference. The refined bake must
// be nearer the truth on both measures, by about half of what it measured or more (+12 points of
// blocks within 10%, RMS 0.062 -> 0.044), so that a rule that refines the wrong place fails. Both
// without the surface fit, which closes most of the same gap on its own and would hide what
// refinement does.
TEST(PictureRefinement, RefinedVolumesBringTheSunlitRoomNearerTheTruth) {
  ScratchDir scratch("picture_refine");
  const RoomPicture plain = room_picture(scratch, "plain", "--refine-budget 0 --surface-fit off");
  const RoomPicture refined = room_picture(scratch, "refined", "--surface-fit off");
  EXPECT_EQ(plain.bake_err.find("refinement: "), std::string::npos) << plain.bake_err;
  EXPECT_NE(refined.bake_err.find("refinement: "), std::string::npos) << refined.bake_err;
  std::printf("two_rooms: unrefined %.1f%% (RMS %.4f), refined %.1f%% (RMS %.4f)\n", 100 * plain.blocks.within,
              plain.rms, 100 * refined.blocks.within, refined.rms);
  EXPECT_GE(refined.blocks.within, plain.blocks.within + 0.05);
  EXPECT_LT(refined.rms, plain.rms - 0.5 * 0.015);
}

// Refinement by the bake's own check (--refine-by-check, bake/pipeline/check_refine.h) with the
// direct-light rule off: the check alone, from what the probes see (not from this camera), must
// find where the unrefined bake misses the truth and refine it, bringing the room nearer the
// truth by about half of what it measured or more (78.1% -> 87.5% of blocks within 10%), so that a
// pass that refines where the check did not miss, or nowhere, fails. A small pass (512 patches of
// 64 paths a point) keeps it quick.
// Both without the surface fit, as above.
TEST(PictureRefinement, TheBakesOwnCheckFindsWhereTheRoomMissesTheTruth) {
  ScratchDir scratch("picture_check_refine");
  const RoomPicture plain = room_picture(scratch, "plain", "--refine-budget 0 --surface-fit off");
  const RoomPicture checked =
      room_picture(scratch, "checked",
                   "--refine-budget 0 --surface-fit off --refine-by-check 8192 --check-patches 32 --check-rays 64");
  EXPECT_NE(checked.bake_err.find("refinement by check: "), std::string::npos) << checked.bake_err;
  EXPECT_NE(checked.bake_err.find("where the bake's check missed"), std::string::npos) << checked.bake_err;
  std::printf("two_rooms: unrefined %.1f%% (RMS %.4f), refined by check %.1f%% (RMS %.4f)\n", 100 * plain.blocks.within,
              plain.rms, 100 * checked.blocks.within, checked.rms);
  EXPECT_GE(checked.blocks.within, plain.blocks.within + 0.045);
}

// Coarse depth tiles (--depth-tile, bake/ddgi/depth_tiles.h) against the same truth: two_rooms'
// sunlit room beside its closed dark room, the wall between them in view, where a visibility test
// that lets light through the wall shows. With 8x8 tiles (final's) the picture must stay that of
// the full tiles within the reference's noise; 4x4 tiles must stay near it.
TEST(PictureDepthTiles, CoarseDepthTilesKeepTheRoomsPicture) {
  ScratchDir scratch("picture_depth_tiles");
  const RoomPicture full = room_picture(scratch, "full", "");
  const RoomPicture eight = room_picture(scratch, "eight", "--depth-tile 8");
  const RoomPicture four = room_picture(scratch, "four", "--depth-tile 4");
  std::printf(
      "two_rooms: depth tiles 16 %.1f%% (median %.3f, RMS %.4f), 8 %.1f%% (median %.3f, RMS %.4f), "
      "4 %.1f%% (median %.3f, RMS %.4f)\n",
      100 * full.blocks.within, full.blocks.median, full.rms, 100 * eight.blocks.within, eight.blocks.median, eight.rms,
      100 * four.blocks.within, four.blocks.median, four.rms);
  EXPECT_GE(eight.blocks.within, full.blocks.within - 0.02);
  EXPECT_LE(eight.rms, full.rms + 0.003);
  EXPECT_NEAR(eight.blocks.median, full.blocks.median, 0.01);
  EXPECT_GE(four.blocks.within, full.blocks.within - 0.05);
  EXPECT_NEAR(four.blocks.median, full.blocks.median, 0.02);
}

const std::string kSample = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
const std::string kTwoRooms = std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/two_rooms.gltf";
const std::string kNvpro = std::string(GIBAKE_ASSETS_DIR) + "/cornell-box-nvpro/cornellBox.gltf";

INSTANTIATE_TEST_SUITE_P(Views, Picture,
                         ::testing::Values(
                             // The bundled sample from its glTF camera: a box lit by a ceiling lamp. Read through the
                             // irradiance atlas (8x8 texels a probe, bilinear) a smooth room scores a little below its
                             // SH, the price of reading sunlit scenes right (docs/BENCHMARKS.md "The irradiance
                             // atlas"); the surface fit gives it back.
                             View{"sample", kSample, "", 0.97, 1.10},
                             // Inside the lit room of two_rooms, lit through a window by the sun and by a small ceiling
                             // patch, looking at the corner of the wall it shares with the closed dark room.
                             View{"two_rooms", kTwoRooms, "--camera -1.9,1.2,0.9,-0.3,0.7,-0.9,0,1,0 --fov 75", 0.97,
                                  1.15},
                             // cornell-box-nvpro from its glTF camera, outside the box's open front: a ceiling lamp,
                             // walls of albedo 1, the walls' front faces seen at the image's rim. Its noise is the
                             // lamp's cavity (docs/BENCHMARKS.md "cornell-box-nvpro: where its noise comes from").
                             // With whole fit paths alone (--fit-gather paths) it reads 72.9%. The sampler's fade of
                             // probes behind the surface costs this small view a few blocks and gains the 256x256 one
                             // (docs/BENCHMARKS.md "Probes behind the surface").
                             View{"nvpro", kNvpro, "", 0.71, 1.20}),
                         [](const ::testing::TestParamInfo<View>& info) { return std::string(info.param.name); });

}  // namespace
