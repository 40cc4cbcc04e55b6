// Help and summaries a new user can read. --help names the program and shows
// examples; bare `gibake` prints the usage; bad numbers get a message saying what was expected;
// --probe-spacing 0 is an error like -1; relocation's second pass is labelled; the seconds line
// uses the user's words; `info` shows the volume first with rounded numbers and no placeholder
// settings; the LPV summary says where its VPLs came from; the voxel dims say why.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file

const std::string kSample = shell_quote(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf");
const std::string kToyCar = shell_quote(std::string(GIBAKE_ASSETS_DIR) + "/toy-car/ToyCar.gltf");

std::string scratch(const std::string& name) {
  return (gibake::test::process_tmp() / ("help_" + name)).string();
}

// The one line of `text` starting with `prefix` (after leading spaces), or "".
std::string line_with(const std::string& text, const std::string& prefix) {
  for (const std::string& line : split_lines(text)) {
    const size_t start = line.find_first_not_of(' ');
    if (start != std::string::npos && line.compare(start, prefix.size(), prefix) == 0) return line;
  }
  return {};
}

TEST(HelpCli, HelpNamesTheProgramAndShowsExamples) {
  const CliResult r = run_gibake_cli("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("Usage: gibake "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Examples:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("'bake' is implied"), std::string::npos) << r.out;
  const CliResult bake = run_gibake_cli("bake --help");
  EXPECT_NE(bake.out.find("Usage: gibake bake "), std::string::npos) << bake.out;
}

TEST(HelpCli, BareGibakePrintsUsage) {
  const CliResult r = run_gibake_cli("");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("Usage: gibake "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Examples:"), std::string::npos) << r.out;
}

TEST(HelpCli, BadNumbersSayWhatWasExpected) {
  const std::string out = " --ddgi --out " + shell_quote(scratch("never.gibake"));
  for (const char* bad : {"--rays -5", "--rays 2.5", "--bounces -1", "--threads -1", "--rays many"}) {
    const CliResult r = run_gibake_cli(kSample + out + " " + bad);
    EXPECT_EQ(r.exit_code, 1) << bad;
    EXPECT_NE(r.err.find("expected a whole number in"), std::string::npos) << bad << ": " << r.err;
    EXPECT_EQ(r.err.find("Could not convert"), std::string::npos) << r.err;
  }
  // Every other number option: what it takes, what it got; never CLI11's "Could not convert".
  const std::pair<const char*, const char*> others[] = {
      {"--grid-padding abc", "--grid-padding: expected a number, got 'abc'"},
      {"--lpv-res x", "--lpv-res: expected a whole number in 4..512, got 'x'"},
      {"--seed -1", "--seed: expected a whole number from 0 to 18446744073709551615, got '-1'"},  // was 2^64-1
  };
  for (const auto& [bad, message] : others) {
    const CliResult r = run_gibake_cli(kSample + out + " " + bad);
    EXPECT_EQ(r.exit_code, 1) << bad;
    EXPECT_NE(r.err.find(message), std::string::npos) << bad << ": " << r.err;
  }
  const CliResult tolerance = run_gibake_cli("verify x.gibake --tolerance x");
  EXPECT_EQ(tolerance.exit_code, 1);
  EXPECT_NE(tolerance.err.find("--tolerance: expected a number, 0 or more, got 'x'"), std::string::npos) << tolerance.err;
  for (const char* spacing : {"0", "-1"}) {  // 0 is refused, not read as the default
    const CliResult r = run_gibake_cli(kSample + out + " --probe-spacing " + spacing);
    EXPECT_EQ(r.exit_code, 1) << spacing;
    EXPECT_NE(r.err.find("--probe-spacing: expected a number above 0"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(scratch("never.gibake")));
}

TEST(SummaryCli, SecondsInUserWordsAndRelocationPasses) {
  const std::string out = scratch("summary.gibake");
  const CliResult r = run_gibake_cli(kSample + " --ddgi --rays 32 --bounces 1 --progress lines --out " + shell_quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string seconds = line_with(r.err, "seconds:");
  ASSERT_FALSE(seconds.empty()) << r.err;
  for (const char* internal : {"(side by side)", "closed-mesh check wait", "task beside", "(solids, queries)",
                               " relocate ", " trace "})
    EXPECT_EQ(seconds.find(internal), std::string::npos) << internal << " in " << seconds;
  for (const char* words : {"import ", "set-up ", "probe relocation ", "ray tracing ", "write ", "total "})
    EXPECT_NE(seconds.find(words), std::string::npos) << words << " missing in " << seconds;
  EXPECT_NE(r.err.find("relocate (pass 2)"), std::string::npos) << r.err;
  fs::remove(out);
}

// What a new user reads of a CPU bake: the backend choice once, no device timings, and the
// adaptive trace's repeats called passes, as the docs call them.
TEST(SummaryCli, BackendOnceNoDeviceTimesOnTheCpuAndTracePasses) {
  const std::string out = scratch("passes.gibake");
  const CliResult b = run_gibake_cli(kSample + " --ddgi --rays 32 --bounces 1 --progress lines --out " + shell_quote(out));
  ASSERT_EQ(b.exit_code, 0) << b.err;
  size_t said = 0;
  for (size_t at = b.err.find("backend auto"); at != std::string::npos; at = b.err.find("backend auto", at + 1)) ++said;
  EXPECT_LE(said, 1u) << b.err;
  if (b.err.find("backend auto \xE2\x86\x92 cpu") != std::string::npos || said == 0) {
    EXPECT_EQ(b.err.find("trace stage:"), std::string::npos) << b.err;
  }
  EXPECT_EQ(b.err.find("(run "), std::string::npos) << b.err;
  EXPECT_NE(b.err.find("trace (pass 2)"), std::string::npos) << b.err;
  fs::remove(out);
}

TEST(SummaryCli, InfoShowsTheVolumeFirstRounded) {
  const std::string out = scratch("info.gibake");
  // One volume: a file of several lists them in its metadata, "counts" included.
  ASSERT_EQ(run_gibake_cli(kSample + " --ddgi --rays 16 --bounces 0 --refine-budget 0 --out " + shell_quote(out)).exit_code,
            0);
  const CliResult r = run_gibake_cli("info " + shell_quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const size_t volume = r.out.find("ddgi volume 0: 8x8x9"), metadata = r.out.find("metadata:");
  ASSERT_NE(volume, std::string::npos) << r.out;
  ASSERT_NE(metadata, std::string::npos) << r.out;
  EXPECT_LT(volume, metadata);
  EXPECT_EQ(r.out.find("0.30000001192092896"), std::string::npos) << r.out;  // float noise
  EXPECT_EQ(r.out.find("\"counts\""), std::string::npos) << r.out;           // the [0,0,0] placeholder
  EXPECT_NE(r.out.find("\"relocate_fraction\": 0.3,"), std::string::npos) << r.out;
  // The JSON keeps every digit.
  const CliResult j = run_gibake_cli("info " + shell_quote(out) + " --format json");
  EXPECT_NE(j.out.find("0.30000001192092896"), std::string::npos);
  fs::remove(out);
}

TEST(SummaryCli, LpvSaysWhereItsVplsCameFromAndVoxelsWhyTheirDims) {
  const std::string out = scratch("lpv.gibake"), vdb = scratch("lpv.vdb");
  const CliResult r = run_gibake_cli(kSample + " --lpv --lpv-res 8 --lpv-samples 1024 --voxel-res 32 --voxels " +
                                     shell_quote(vdb) + " --out " + shell_quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string lights = line_with(r.err, "lpv lights:");
  // The total is the lit-surface VPLs plus the emissive ones, each with its own source named.
  unsigned long long total = 0, lit = 0, rays = 0, emissive = 0;
  ASSERT_EQ(std::sscanf(lights.c_str(), " lpv lights: %llu VPLs in all: %llu where %llu rays from the lights met a "
                                        "surface, %llu on emissive surfaces",
                        &total, &lit, &rays, &emissive),
            4)
      << lights;
  EXPECT_EQ(rays, 1024u);
  EXPECT_EQ(emissive, 1024u);
  EXPECT_GT(lit, 0u);
  EXPECT_LE(lit, rays);
  EXPECT_EQ(total, lit + emissive);
  const std::string voxels = line_with(r.err, "voxels (");
  EXPECT_NE(voxels.find("35x"), std::string::npos) << voxels;
  EXPECT_NE(voxels.find("32 across the scene's longest side (--voxel-res), plus one empty voxel on every side"),
            std::string::npos)
      << voxels;
  fs::remove(out);
  fs::remove(vdb);
}

TEST(SummaryCli, OneProbeGridSaysWhereItIs) {
  const std::string out = scratch("car.gibake");
  const CliResult r = run_gibake_cli(kToyCar + " --ddgi --probe-counts 1,1,1 --rays 16 --bounces 0 --sun 0,-1,0:1000 --progress lines --out " +
                                     shell_quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("probe grid 1x1x1 = 1 probe, at ("), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("spacing 0 x 0 x 0"), std::string::npos) << r.err;
  fs::remove(out);
}

}  // namespace
