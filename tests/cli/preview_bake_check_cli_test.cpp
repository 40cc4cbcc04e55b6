// `preview` checks that the bake was made from the scene (its input hash), an
// error unless --force, and that --camera-index and --volume name a camera and a volume there are;
// a bake of LPV cascades alone previews through the LPV sampler.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file, ScratchDir

const std::string kSample = shell_quote(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf");
const std::string kNvpro = shell_quote(std::string(GIBAKE_ASSETS_DIR) + "/cornell-box-nvpro/cornellBox.gltf");

class PreviewBakeCheck : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return shell_quote(scratch_.path(name)); }
  ScratchDir scratch_{"preview_check"};
  const fs::path& dir_ = scratch_.dir();
};

TEST_F(PreviewBakeCheck, AnotherScenesBakeIsRefusedUnlessForced) {
  ASSERT_EQ(run_gibake_cli(kSample + " --ddgi --probe-counts 3,3,3 --rays 16 --bounces 0 --out " + path("c.gibake")).exit_code,
            0);
  const std::string view = " --bake " + path("c.gibake") + " --size 64x36 --progress lines --out ";
  // The bake's own scene: no word about it.
  const CliResult own = run_gibake_cli("preview " + kSample + view + path("own.png"));
  EXPECT_EQ(own.exit_code, 0) << own.err;
  EXPECT_EQ(own.err.find("was not baked from"), std::string::npos) << own.err;
  // Another scene: one error line, exit 1, no image.
  const CliResult other = run_gibake_cli("preview " + kNvpro + view + path("other.png"));
  EXPECT_EQ(other.exit_code, 1) << other.err;
  const std::string error = split_lines(other.err).empty() ? "" : split_lines(other.err).back();
  EXPECT_EQ(error.rfind("gibake: error: ", 0), 0u) << other.err;
  EXPECT_NE(error.find("was not baked from"), std::string::npos) << error;
  EXPECT_NE(error.find("--force"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir_ / "other.png"));
  // --force: a warning, and the image.
  const CliResult forced = run_gibake_cli("preview " + kNvpro + view + path("forced.png") + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(forced.err.find("gibake: warning: "), std::string::npos) << forced.err;
  EXPECT_TRUE(fs::exists(dir_ / "forced.png"));
}

// --camera-index and --volume past what the scene and the bake hold are the arguments' fault
// (exit 1), one line naming the option, the value and how many there are; no image.
TEST_F(PreviewBakeCheck, IndicesPastTheSceneOrBakeAreRefused) {
  ASSERT_EQ(
      run_gibake_cli(kSample + " --ddgi --probe-counts 2,2,2 --rays 16 --bounces 0 --reconstruction-check off --out " +
                     path("c.gibake"))
          .exit_code,
      0);
  const std::string view = "preview " + kSample + " --bake " + path("c.gibake") + " --size 8x8 --out " + path("v.png");
  const std::string scene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  CliResult r = run_gibake_cli(view + " --camera-index 99");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  ASSERT_FALSE(split_lines(r.err).empty());
  EXPECT_EQ(
      split_lines(r.err).back(),
      "gibake: error: " + scene + ": --camera-index: asked for camera 99, but the scene has 1 glTF camera (0..0)");
  r = run_gibake_cli(view + " --volume 5");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  ASSERT_FALSE(split_lines(r.err).empty());
  EXPECT_EQ(split_lines(r.err).back(),
            "gibake: error: " + scratch_.path("c.gibake") +
                ": --volume: asked for volume 5, but the bake file has 1 DDGI volume (0..0)");
  EXPECT_FALSE(fs::exists(dir_ / "v.png"));
  // An index beside --camera, which would go unused, is refused before the import.
  r = run_gibake_cli(view + " --camera-index 0 --camera 0,1,3,0,1,0,0,1,0");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(split_lines(r.err).size(), 1u) << r.err;
  EXPECT_EQ(split_lines(r.err).back(),
            "gibake: error: --camera-index: picks a glTF camera, but --camera gives the view itself; give one of them");
  EXPECT_FALSE(fs::exists(dir_ / "v.png"));
  // In range, or --camera alone, preview as before.
  EXPECT_EQ(run_gibake_cli(view + " --camera-index 0 --volume 0").exit_code, 0);
  EXPECT_EQ(run_gibake_cli(view + " --camera 0,1,3,0,1,0,0,1,0").exit_code, 0);
}

TEST_F(PreviewBakeCheck, LpvOnlyBakePreviewsThroughTheLpv) {
  ASSERT_EQ(run_gibake_cli(kSample + " --lpv --lpv-res 8 --lpv-samples 1024 --out " + path("l.gibake")).exit_code, 0);
  for (const char* mode : {"lit", "indirect"}) {
    const CliResult r = run_gibake_cli("preview " + kSample + " --bake " + path("l.gibake") + " --mode " + mode +
                                       " --size 64x36 --out " + path(std::string(mode) + ".png"));
    EXPECT_EQ(r.exit_code, 0) << mode << ": " << r.err;
    EXPECT_EQ(r.err.find("--volume"), std::string::npos) << r.err;  // no flag the user never passed
    EXPECT_TRUE(fs::exists(dir_ / (std::string(mode) + ".png"))) << mode;
  }
  // --volume picks a DDGI volume; with none in the file it would go unused.
  const CliResult volume = run_gibake_cli("preview " + kSample + " --bake " + path("l.gibake") +
                                          " --volume 0 --size 64x36 --out " + path("v0.png"));
  EXPECT_EQ(volume.exit_code, 1) << volume.err;
  EXPECT_NE(volume.err.find(": --volume: asked for volume 0, but the bake file has no DDGI volume"), std::string::npos)
      << volume.err;
  EXPECT_FALSE(fs::exists(dir_ / "v0.png"));
  const CliResult probes = run_gibake_cli("preview " + kSample + " --bake " + path("l.gibake") +
                                          " --mode probes --size 64x36 --out " + path("probes.png"));
  EXPECT_EQ(probes.exit_code, 1) << probes.err;
  EXPECT_NE(probes.err.find("no DDGI probes"), std::string::npos) << probes.err;
}

}  // namespace

namespace {

// The reconstruction line a command printed ("reconstruction error (...)" up to its seconds).
std::string reconstruction_line(const std::string& text) {
  const size_t at = text.find("reconstruction error (");
  if (at == std::string::npos) return "";
  const size_t end = text.find("; 0.", at);  // the seconds differ between runs
  return text.substr(at, end == std::string::npos ? std::string::npos : end - at);
}

// --check-camera: the bake's check takes its patches from the views a user names, and measures
// there exactly what `preview --size 320x180 --check-patches` measures for the same view (the
// same patches, points and reference paths: the same line to the digit). Several views share the
// patches; a malformed view or a glTF camera the scene lacks is refused before anything is written.
TEST_F(PreviewBakeCheck, TheBakesCheckFromACameraIsPreviewsCheck) {
  const std::string bake = path("cam.gibake");
  const std::string settings = " --ddgi --rays 64 --max-rays 256 --ray-budget 128 --bounces 2 --check-patches 48";
  const CliResult one = run_gibake_cli(kSample + settings + " --check-camera default --out " + bake);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const std::string baked = reconstruction_line(one.err);
  EXPECT_NE(baked.find("(camera, "), std::string::npos) << one.err;
  const CliResult preview = run_gibake_cli("preview " + kSample + " --bake " + bake +
                                           " --size 320x180 --check-patches 48 --out " + path("cam.png"));
  ASSERT_EQ(preview.exit_code, 0) << preview.err;
  EXPECT_EQ(reconstruction_line(preview.out + preview.err), baked);

  // Two views; the report's views come from the first, so the patches it marks are those it shows.
  const CliResult two =
      run_gibake_cli(kSample + settings + " --check-camera 0,1,1.8,0,1,0,0,1,0 --check-camera default" + " --report " +
                     path("cam.html") + " --out " + bake);
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_NE(reconstruction_line(two.err).find("(2 cameras, "), std::string::npos) << two.err;
  const std::string page = read_text_file(scratch_.path("cam.html"));
  EXPECT_NE(page.find("lit (camera from --camera, EV100"), std::string::npos);
  EXPECT_EQ(page.find("lit (glTF camera"), std::string::npos);

  for (const char* bad : {"gltf:x", "1,2,3", "gltf:7"}) {
    const CliResult r = run_gibake_cli(kSample + " --ddgi --check-camera " + bad + " --out " + path("bad.gibake"));
    EXPECT_EQ(r.exit_code, 1) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--check-camera"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad.gibake")) << bad;
  }
}

}  // namespace

namespace {

using namespace gibake::test;

// --explain: the pixel's probes and truths on stdout, no image needed; a pixel outside the image,
// or no bake, is one error line and exit 1.
TEST(PreviewExplain, PrintsThePixelsProbesAndTruthsAndRefusesAPixelOutside) {
  ScratchDir scratch{"preview_explain"};
  const std::string bake = shell_quote(scratch.path("c.gibake"));
  ASSERT_EQ(run_gibake_cli(kSample + " --ddgi --probe-counts 4,4,4 --rays 64 --out " + bake).exit_code, 0);
  const std::string view = "preview " + kSample + " --bake " + bake + " --size 64x48 --explain-paths 256 --explain ";
  const CliResult r = run_gibake_cli(view + "32,24");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* line : {"pixel 32,24 of the 64x48 view", "surface: triangle ", "path-traced here", "exact probes",
                           "the error in two: the probes' own", "probes ("})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(scratch.dir()), {}), 1);  // the bake alone: no image
  for (const std::string& bad : {std::string("64,0"), std::string("1,-1"), std::string("3")}) {
    const CliResult e = run_gibake_cli(view + bad);
    EXPECT_EQ(e.exit_code, 1) << bad << ": " << e.err;
    ASSERT_EQ(split_lines(e.err).size(), 1u) << e.err;
    EXPECT_NE(e.err.find("--explain"), std::string::npos) << e.err;
  }
  const CliResult no_bake = run_gibake_cli("preview " + kSample + " --explain 1,1");
  EXPECT_EQ(no_bake.exit_code, 1) << no_bake.err;
  EXPECT_NE(no_bake.err.find("needs --bake"), std::string::npos) << no_bake.err;
}

}  // namespace
