// --max-memory: one cap on the estimated host memory of every bake kind. A bake over it is refused
// before any output in one line naming the estimate and the option (exit 1); a larger cap lets the
// same bake through.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines

const std::string kSample = shell_quote(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf");
// A cheap DDGI bake: one batch of few rays a probe, no check.
const std::string kCheapDdgi = " --ddgi --rays 16 --target-error 0 --reconstruction-check off --threads 2";

// The last stderr line (progress comes before it) must be the error and name the figure and option.
std::string refusal(const std::string& args, const fs::path& out) {
  const CliResult r = run_gibake_cli(args);
  EXPECT_EQ(r.exit_code, 1) << args << "\n" << r.err;
  EXPECT_FALSE(fs::exists(out)) << "no partial output";
  const std::vector<std::string> lines = split_lines(r.err);
  EXPECT_FALSE(lines.empty());
  const std::string last = lines.empty() ? std::string() : lines.back();
  EXPECT_EQ(last.rfind("gibake: error: ", 0), 0u) << last;
  EXPECT_NE(last.find("--max-memory"), std::string::npos) << last;
  return last;
}

TEST(MemoryCli, DdgiOverTheCapIsRefusedWithTheFigureAndALargerCapLetsItThrough) {
  ScratchDir dir("memory_ddgi");
  const fs::path out = dir.path("probes.bin");
  const std::string bake = "bake " + kSample + kCheapDdgi + " --out " + shell_quote(out.string());
  const std::string line = refusal(bake + " --refine-budget 0 --max-memory 1M", out);
  EXPECT_NE(line.find("would need about"), std::string::npos) << line;
  EXPECT_NE(line.find("MiB of host memory, over the 1 MiB of --max-memory"), std::string::npos) << line;
  // Refinement's voxels (bake/ddgi/refine.h) are held to the same cap, and the line names the way out.
  const std::string refined = refusal(bake + " --max-memory 1M", out);
  EXPECT_NE(refined.find("refinement: "), std::string::npos) << refined;
  EXPECT_NE(refined.find("over the 1.0 MiB of --max-memory"), std::string::npos) << refined;
  EXPECT_NE(refined.find("--refine-budget 0"), std::string::npos) << refined;
  const CliResult ok = run_gibake_cli(bake + " --max-memory 4G");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_NE(ok.err.find("MiB of host memory estimated (--max-memory 4096 MiB)"), std::string::npos) << ok.err;
}

TEST(MemoryCli, LpvVoxelsAndVoxelGiShareTheCap) {
  ScratchDir dir("memory_kinds");
  const fs::path out = dir.path("gi.bin");
  const fs::path vdb = dir.path("scene.vdb");
  refusal("bake " + kSample + " --lpv --max-memory 1K --out " + shell_quote(out.string()), out);
  refusal("bake " + kSample + " --vxgi --max-memory 1K --out " + shell_quote(out.string()), out);
  refusal("bake " + kSample + " --voxels " + shell_quote(vdb.string()) + " --max-memory 1K", vdb);
}

TEST(MemoryCli, SizesAreBytesOrBinaryUnitsAboveZero) {
  for (const char* bad : {"lots", "-5", "0", "12Q"}) {
    const CliResult r = run_gibake_cli("bake " + kSample + " --ddgi --max-memory " + bad + " --out /dev/null");
    EXPECT_EQ(r.exit_code, 1) << bad << "\n" << r.err;
    EXPECT_EQ(split_lines(r.err).size(), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("gibake: error: --max-memory: ", 0), 0u) << r.err;
  }
}

}  // namespace
