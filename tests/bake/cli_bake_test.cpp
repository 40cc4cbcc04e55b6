// The bake command end to end: exit codes and a written file.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/support/cli_run.h"

namespace {
int run(const std::string& args) { return gibake::test::run_gibake_cli(args).exit_code; }
const std::string kSaw = std::string(GIBAKE_ASSETS_DIR) + "/reciprocating-saw/ReciprocatingSaw.gltf";
}  // namespace

TEST(BakeCli, WritesProbesAndReportsBadArguments) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "gibake_bake_cli_test.bin";
  std::filesystem::remove(out);
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() +
                " --probe-counts 3,3,3 --rays 64 --bounces 1 --sun 0,-1,0:1000 --sky 0.1,0.1,0.1 --progress json"),
            0);
  EXPECT_TRUE(std::filesystem::exists(out));
  EXPECT_GT(std::filesystem::file_size(out), 1000u);
  std::filesystem::remove(out);
  EXPECT_EQ(run(kSaw + " --out " + out.string()), 1);                          // no --ddgi
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --sun 1,2"), 1);    // malformed --sun
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --sh-order 3"), 1);  // unsupported order
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --probe-spacing 0.0001"), 1);  // probe cap
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --sky-hdr /nonexistent/sky.exr"), 2);
  EXPECT_FALSE(std::filesystem::exists(out));
}

// The grid the default rule chose is printed before baking; --gather takes path or probes.
using gibake::test::CliResult;
using gibake::test::run_gibake_cli;
using gibake::test::shell_quote;
TEST(BakeCli, PrintsTheDefaultGridAndParsesGather) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "gibake_bake_cli_grid.bin";
  const std::string sample = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  const CliResult r = run_gibake_cli(shell_quote(sample) + " --ddgi --rays 32 --bounces 1 --progress lines --out " +
                                     shell_quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The sample is a 2 m room: longest side / 24 is below the 0.25 m floor, so 8 cells per axis, and
  // one layer of probes in front of its open front (+z: the walls end there, facing the camera).
  EXPECT_NE(r.err.find("probe grid 8x8x9 = 576 probes, spacing 0.25 x 0.25 x 0.25 m"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("one layer of probes outside the open side +z"), std::string::npos) << r.err;
  EXPECT_NE(
      r.err.find(
          "(default spacing rule: longest side / 24 within 0.25..1 m, at least 8 cells across, budget 32768 probes)"),
      std::string::npos)
      << r.err;
  EXPECT_EQ(run(shell_quote(sample) + " --ddgi --rays 32 --gather probes --out " + out.string()), 0);
  EXPECT_EQ(run(shell_quote(sample) + " --ddgi --rays 32 --gather photons --out " + out.string()), 1);
  std::filesystem::remove(out);
}
