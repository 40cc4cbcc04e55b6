// One parser per option kind. Every command that takes --sun, on|off, --threads or
// a vec3 answers a bad value with the same one-line message, naming the option and what it got.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file

const std::string kSample = shell_quote(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf");

std::string out_file(const std::string& ext) {
  return shell_quote((gibake::test::process_tmp() / ("options" + ext)).string());
}

// Exit 1 and exactly one line, the error, ending in `what` (the option's own message).
std::string error_of(const std::string& args) {
  const CliResult r = run_gibake_cli(args);
  EXPECT_EQ(r.exit_code, 1) << args << "\n" << r.err;
  const std::vector<std::string> lines = split_lines(r.err);
  EXPECT_EQ(lines.size(), 1u) << r.err;
  return lines.empty() ? std::string() : lines[0];
}

TEST(OptionsCli, OnOffSaysWhatItGot) {
  for (const char* option : {"--relocate", "--closed-mesh-check", "--voxel-sdf", "--leak-audit"})
    EXPECT_EQ(error_of(kSample + " --ddgi --out " + out_file(".gibake") + " " + option + " maybe"),
              std::string("gibake: error: ") + option + ": expected 'on' or 'off', got 'maybe'");
  EXPECT_EQ(error_of("inspect " + kSample + " --leak-audit maybe"),
            "gibake: error: --leak-audit: expected 'on' or 'off', got 'maybe'");
}

TEST(OptionsCli, SunIsParsedTheSameEverywhere) {
  const std::string bake = error_of(kSample + " --ddgi --out " + out_file(".gibake") + " --sun 1,2:5");
  const std::string preview = error_of("preview " + kSample + " --mode albedo --out " + out_file(".png") + " --sun 1,2:5");
  const std::string inspect = error_of("inspect " + kSample + " --sun 1,2:5");
  EXPECT_EQ(bake, "gibake: error: --sun: expected three numbers x,y,z, got '1,2'");
  EXPECT_EQ(preview, bake);
  EXPECT_EQ(inspect, bake);
  EXPECT_EQ(error_of(kSample + " --ddgi --out " + out_file(".gibake") + " --sun 0,-1,0:-3"),
            error_of("preview " + kSample + " --mode albedo --out " + out_file(".png") + " --sun 0,-1,0:-3"));
}

TEST(OptionsCli, ThreadCapAndVec3AreTheSameEverywhere) {
  const std::string bake = error_of(kSample + " --ddgi --out " + out_file(".gibake") + " --threads 5000");
  EXPECT_EQ(bake, "gibake: error: --threads: expected a whole number in 0..1024, got '5000'");
  EXPECT_EQ(error_of("preview " + kSample + " --mode albedo --out " + out_file(".png") + " --threads 5000"), bake);
  EXPECT_EQ(error_of(kSample + " --ddgi --out " + out_file(".gibake") + " --sky 1,x,1"),
            error_of("preview " + kSample + " --mode albedo --out " + out_file(".png") + " --sky 1,x,1"));
  EXPECT_EQ(error_of(kSample + " --ddgi --out " + out_file(".gibake") + " --backend gpu"),
            "gibake: error: --backend: expected 'auto', 'cpu' or 'vulkan', got 'gpu'");
}

// A number option takes no NaN, infinity or value beyond a float, in any command: comparisons
// with a range let NaN through, and a bake would read it as a setting (a grid at NaN, a skipped
// check) instead of refusing it.
TEST(OptionsCli, NumbersAreFiniteEverywhere) {
  const std::string bake = kSample + " --ddgi --out " + out_file(".gibake");
  EXPECT_EQ(error_of(bake + " --check-noise nan"), "gibake: error: --check-noise: expected a finite number, got 'nan'");
  EXPECT_EQ(error_of(bake + " --grid-padding inf"),
            "gibake: error: --grid-padding: expected a finite number, got 'inf'");
  EXPECT_EQ(error_of(bake + " --target-error 1e39"),
            "gibake: error: --target-error: expected a finite number, got '1e39'");
  EXPECT_EQ(error_of(bake + " --target-error 2"),
            "gibake: error: --target-error: expected a number from 0 to 1, got '2'");
  EXPECT_EQ(error_of("preview " + kSample + " --mode albedo --out " + out_file(".png") + " --exposure nan"),
            "gibake: error: --exposure: expected a finite number, got 'nan'");
  EXPECT_EQ(error_of(bake + " --sky-hdr-scale -1"),
            "gibake: error: --sky-hdr-scale: expected a number, 0 or more, got '-1'");
  EXPECT_EQ(error_of("preview " + kSample + " --mode albedo --out " + out_file(".png") + " --diff-floor -1"),
            "gibake: error: --diff-floor: expected a number, 0 or more, got '-1'");
  EXPECT_EQ(error_of(bake + " --sun 0,-1,0:1e39"),
            "gibake: error: --sun: illuminance (lux) must be a number from 0 to 3.4e38 in '0,-1,0:1e39'");
  // Not 0 in the text, 0 as a float: it would read as 0, which for a spacing means "unset".
  EXPECT_EQ(error_of(bake + " --probe-spacing 1e-46"),
            "gibake: error: --probe-spacing: '1e-46' is too small for a float: it would read as 0");
  EXPECT_EQ(error_of(bake + " --probe-volume -1,0,-1:1,2,1:1e-300"),
            "gibake: error: --probe-volume: the spacing must be a positive number of metres, got '1e-300'");
  // A range's whole bounds in full, not in CLI11's exponent.
  EXPECT_EQ(error_of(bake + " --check-patches 0"),
            "gibake: error: --check-patches: expected a number from 1 to 1048576, got '0'");
  EXPECT_FALSE(fs::exists((gibake::test::process_tmp() / "options.gibake")));
}

// An empty path (an unset shell variable) is refused wherever a file or folder is named, rather
// than switching the action off: export would write nothing and exit 0, verify skip its check.
TEST(OptionsCli, EmptyPathsAreRefused) {
  const std::string bake_file = out_file(".gibake");
  for (const std::string& args : {"export " + bake_file + " --exr ''", "export " + bake_file + " --vdb ''",
                                  "verify " + bake_file + " --against ''", "verify " + bake_file + " --scene ''",
                                  kSample + " --ddgi --out ''", "sample " + bake_file + " --source ddgi --points ''"}) {
    const std::string line = error_of(args);
    EXPECT_NE(line.find(": expected a path, got ''"), std::string::npos) << args << "\n" << line;
  }
}

// An option that only qualifies another is refused without it, rather than ignored.
TEST(OptionsCli, QualifiersNeedWhatTheyQualify) {
  const std::string bake = kSample + " --ddgi --out " + out_file(".gibake");
  EXPECT_EQ(error_of(bake + " --near-fov 40"),
            "gibake: error: --near-fov: only with --near-camera (the view it widens)");
  EXPECT_EQ(error_of(bake + " --check-fov 40"),
            "gibake: error: --check-fov: only with --check-camera (the view it widens)");
  const std::string verify = "verify " + out_file(".gibake");
  EXPECT_EQ(error_of(verify + " --tolerance 1e-3"),
            "gibake: error: --compare, --tolerance: only with --against (the reference they compare with)");
  EXPECT_EQ(error_of(verify + " --compare statistical"),
            "gibake: error: --compare, --tolerance: only with --against (the reference they compare with)");
  EXPECT_EQ(error_of(verify + " --against " + out_file(".gibake") + " --compare statistical --sigmas 0"),
            "gibake: error: --sigmas: expected a number above 0, got '0'");
  // The scale of the probes' feedback passes: a path gather has none, yet the file recorded it.
  EXPECT_EQ(error_of(bake + " --energy-conservation 0.5"),
            "gibake: error: --energy-conservation: scales the passes of --gather probes; a path gather traces every "
            "bounce as it is: drop it, or add --gather probes");
  // --from-shards takes every word after it; an option there was meant as one.
  EXPECT_EQ(error_of(kSample + " --from-shards --ddgi --out " + out_file(".gibake")),
            "gibake: error: --from-shards: takes the shard files, got the option --ddgi: give the parts after the "
            "other options, or --from-shards last");
  EXPECT_EQ(error_of(kSample + " --lpv --lpv-samples 0 --out " + out_file(".gibake")),
            "gibake: error: --lpv-samples: expected a whole number in 1..4294967295, got '0'");
  EXPECT_EQ(
      error_of("merge " + out_file(".gibake") + " --out " + out_file("m.gibake") + " --backend cpu --vulkan-device 0"),
      "gibake: error: --vulkan-device: names a device for --backend vulkan or auto");
}

// A view given as eye,target,up is the view written: eye and target apart, up neither zero nor
// along the view (it was replaced by a guess), in preview, the check and the near volumes alike.
TEST(OptionsCli, ViewsAreWhatWasWritten) {
  const std::string preview = "preview " + kSample + " --out " + out_file(".png") + " --camera ";
  EXPECT_EQ(error_of(preview + "0,1,3,0,1,3,0,1,0"),
            "gibake: error: --camera: eye and target must differ, got '0,1,3,0,1,3,0,1,0'");
  EXPECT_EQ(error_of(preview + "0,1,3,0,1,0,0,0,2"),
            "gibake: error: --camera: the up vector must be neither zero nor along the view (eye to target), got "
            "'0,1,3,0,1,0,0,0,2'");
  const std::string bake = kSample + " --ddgi --out " + out_file(".gibake");
  EXPECT_EQ(error_of(bake + " --near-camera 0,1,3,0,1,0,0,0,0"),
            "gibake: error: --near-camera: the up vector must be neither zero nor along the view (eye to target), got "
            "'0,1,3,0,1,0,0,0,0'");
  EXPECT_FALSE(fs::exists((gibake::test::process_tmp() / "options.png")));
}

// --probe-budget bounds the spacing rule's volumes; where no volume follows the rule it would be
// ignored, so it is refused before the import. Beside a --probe-volume without a spacing it holds.
TEST(OptionsCli, ProbeBudgetOnlyWhereTheRulePlaces) {
  const std::string bake = kSample + " --ddgi --out " + out_file(".gibake") + " --probe-budget 8";
  const std::string rule =
      "gibake: error: --probe-budget: bounds only the probes the spacing rule places, and --probe-spacing or "
      "--probe-counts sets the grid";
  EXPECT_EQ(error_of(bake + " --probe-spacing 0.3"), rule + "; drop it, or the spacing");
  EXPECT_EQ(error_of(bake + " --probe-counts 4,4,4 --probe-volume -1,0,-1:1,2,1:0.5"),
            rule + " and every --probe-volume has its spacing; drop it, or the spacing");
  EXPECT_FALSE(fs::exists((gibake::test::process_tmp() / "options.gibake")));
  const std::string ruled_out = (gibake::test::process_tmp() / "options_ruled_box.gibake").string();
  const CliResult ruled_box = run_gibake_cli(kSample + " --ddgi --probe-budget 8 --out " + shell_quote(ruled_out) +
                                             " --probe-counts 2,2,2 --rays 16 --surface-fit off --refine-budget 0 "
                                             "--probe-volume -0.5,0.2,-0.5:0.5,1.5,0.5");
  EXPECT_EQ(ruled_box.exit_code, 0) << ruled_box.err;
  fs::remove(ruled_out);
}

// An explicit grid box spans every axis of more than one probe, refused before the import.
TEST(OptionsCli, GridBoxSpansItsProbes) {
  const std::string bake = kSample + " --ddgi --out " + out_file(".gibake") + " --probe-counts 4,1,4";
  const std::string rule =
      "gibake: error: --grid-max: must lie above --grid-min on every axis of more than one probe, and not below it on "
      "any ";
  EXPECT_EQ(error_of(bake + " --grid-min 0,0,0 --grid-max 0,0,1"), rule + "(axis x: 0 to 0)");  // 4 probes, no width
  EXPECT_EQ(error_of(bake + " --grid-min 0,1,0 --grid-max 1,0.5,1"), rule + "(axis y: 1 to 0.5)");  // inverted
  EXPECT_FALSE(fs::exists((gibake::test::process_tmp() / "options.gibake")));
}

// Places rays start from (eyes, box corners) lie within the tracer's range, as the scene's do.
TEST(OptionsCli, PlacesStayWithinTheTracersRange) {
  const std::string bake = kSample + " --ddgi --out " + out_file(".gibake");
  EXPECT_EQ(error_of(bake + " --probe-volume 0,0,0:1e19,1,1"),
            "gibake: error: --probe-volume: places lie within 1e+16 m of the origin (the ray tracer's range), got "
            "'0,0,0:1e19,1,1'");
  EXPECT_EQ(error_of(bake + " --near-camera 1e19,0,0,0,0,0,0,1,0"),
            "gibake: error: --near-camera: places lie within 1e+16 m of the origin (the ray tracer's range), got "
            "'1e19,0,0,0,0,0,0,1,0'");
}

// CLI11's own wording for a repeated option or a size it cannot read, in the user's words.
TEST(OptionsCli, RepeatsAndSizesSayWhatTheyTake) {
  const std::string bake = kSample + " --ddgi --out " + out_file(".gibake");
  EXPECT_EQ(error_of(bake + " --out " + out_file("2.gibake")),
            "gibake: error: --out: given 2 times; it takes one value");
  EXPECT_EQ(error_of(bake + " --max-memory 1e99"),
            "gibake: error: --max-memory: expected a size above 0 such as 512M or 16G, got '1e99'");
  EXPECT_EQ(error_of(bake + " --max-memory 16E"),
            "gibake: error: --max-memory: expected a size within 16E (2^64 - 1 bytes), got '16E'");
  EXPECT_EQ(error_of(bake + " --max-memory 0"), "gibake: error: --max-memory: expected a size above 0, got '0'");
}

}  // namespace
