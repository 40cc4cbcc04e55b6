// --max-memory: one cap on the estimated host memory of every bake kind. A bake over it is refused
// before any output in one line naming the estimate and the option (exit 1); a larger cap lets the
// same bake through.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "bake/ddgi/ddgi_memory.h"
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
  // A cap below a unit is named as given, not rounded down to "0 MiB".
  const std::string one_byte = refusal(bake + " --refine-budget 0 --max-memory 1", out);
  EXPECT_NE(one_byte.find("over the 1 byte of --max-memory"), std::string::npos) << one_byte;
  // Refinement's voxels (bake/ddgi/refine.h) are held to the same cap, and the line names the way out.
  const std::string refined = refusal(bake + " --max-memory 1M", out);
  EXPECT_NE(refined.find("refinement: "), std::string::npos) << refined;
  EXPECT_NE(refined.find("over the 1 MiB of --max-memory"), std::string::npos) << refined;
  EXPECT_NE(refined.find("--refine-budget 0"), std::string::npos) << refined;
  const CliResult ok = run_gibake_cli(bake + " --max-memory 4G");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_NE(ok.err.find("MiB of host memory estimated (--max-memory 4 GiB)"), std::string::npos) << ok.err;
}

// With --backend auto the route is not chosen when the bake is first judged, so it is judged on the
// lighter route's figure and again on the chosen one's: a cap the CPU route fits passes, where the
// Vulkan route's figure (its staging) would have refused it before the choice.
TEST(MemoryCli, AutoIsJudgedOnTheLighterRouteUntilItHasChosen) {
  ScratchDir dir("memory_auto");
  const std::string bake = "bake " + kSample + kCheapDdgi + " --refine-budget 0 --progress lines --out ";
  const CliResult cpu = run_gibake_cli(bake + shell_quote(dir.path("cpu.gibake")) + " --backend cpu");
  ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
  const long cpu_mib = noted_memory_mib(cpu);
  ASSERT_GT(cpu_mib, 0) << cpu.err;
  gibake::DdgiMemoryShape device;  // the staging alone, which only the Vulkan route holds
  device.vulkan = true;
  ASSERT_GT(gibake::estimate_ddgi_memory(device).total() >> 20, uint64_t(cpu_mib) + 64);
  const std::string cap = " --max-memory " + std::to_string(cpu_mib + 32) + "M";
  const CliResult r = run_gibake_cli(bake + shell_quote(dir.path("auto.gibake")) + " --backend auto" + cap);
  if (r.err.find("backend auto → vulkan") != std::string::npos) GTEST_SKIP() << "auto chose a GPU here: " << r.err;
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(noted_memory_mib(r), cpu_mib) << r.err;
}

// The estimate counts the write buffer (the writer encodes the whole file in one) and, in a bake of
// several volumes, every volume's result until the write (bake/ddgi/ddgi_memory.h). Its file bytes
// are the file's: summed over the volumes of a default bake (the grid and its refined volumes),
// with and without the irradiance atlas and with final's 8x8 depth tiles, they fall short of the file by its header,
// table and metadata only; what a volume holds, from its probe count alone, is its f32 result and its f16 part of the
// file, about three times that part. The grid's bake runs beside the refinement and counts its voxels into the
// estimate it notes (more than the same grid's estimate without them); the refined volumes' estimate, noted as the
// largest, counts every volume's result.
TEST(MemoryCli, TheEstimateCountsTheFileAndEveryVolumesResult) {
  ScratchDir dir("memory_file");
  const CliResult grid_only = run_gibake_cli("bake " + kSample + kCheapDdgi + " --refine-budget 0 --out " +
                                             shell_quote(dir.path("grid.gibake")));
  ASSERT_EQ(grid_only.exit_code, 0) << grid_only.err;
  struct Storage {
    const char* args;
    bool irradiance_atlas;
    int depth_tile;
  };
  for (const Storage& st : {Storage{"--irradiance-atlas on", true, 16}, Storage{"--irradiance-atlas off", false, 16},
                            Storage{"--irradiance-atlas off --depth-tile 8", false, 8}}) {
    SCOPED_TRACE(st.args);
    const fs::path out =
        dir.path("probes_" + std::to_string(st.depth_tile) + (st.irradiance_atlas ? "_atlas" : "") + ".gibake");
    const CliResult r =
        run_gibake_cli("bake " + kSample + kCheapDdgi + " " + st.args + " --out " + shell_quote(out.string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const CliResult info = run_gibake_cli("info " + shell_quote(out.string()) + " --format json");
    ASSERT_EQ(info.exit_code, 0) << info.err;
    const nlohmann::json volumes = nlohmann::json::parse(info.out)["ddgi"];
    ASSERT_GE(volumes.size(), 2u) << "the default bake refines: the test needs several volumes";
    uint64_t file = 0, held = 0;
    for (const nlohmann::json& v : volumes) {
      const uint64_t probes = v["probe_count"];
      const int coefs = v["sh_coefficients"];
      auto area = [&](const char* key) {
        return v.contains(key) ? v[key]["width"].get<uint64_t>() * v[key]["height"].get<uint64_t>() : 0;
      };
      EXPECT_EQ(v["depth_atlas"]["tile"].get<int>(), st.depth_tile);
      file += gibake::ddgi_file_bytes(probes, coefs, area("irradiance_atlas"), area("depth_atlas"));
      const uint64_t volume_held = gibake::ddgi_held_bytes(probes, coefs, st.irradiance_atlas, st.depth_tile);
      held += volume_held;
    }
    if (st.irradiance_atlas) {
      EXPECT_GE(noted_memory_mib(grid_only), 1.0) << grid_only.err;
      EXPECT_GE(noted_memory_mib(r) - noted_memory_mib(grid_only), 1.0) << r.err;  // the refinement's voxels, beside
      // The notes round down to MiB.
      const std::string largest = " MiB of host memory estimated for volume 1 (refined), the largest";
      const size_t at = r.err.find(largest);
      ASSERT_NE(at, std::string::npos) << r.err;
      const size_t from = r.err.rfind("memory: about ", at) + 14;
      EXPECT_GE(std::stod(r.err.substr(from, at - from)) + 1.0, double(held) / (1 << 20)) << r.err;
    }
    const uint64_t size = fs::file_size(out);
    EXPECT_LE(file, size);
    EXPECT_GT(double(file), 0.98 * double(size)) << file << " of " << size << " bytes";
    EXPECT_GT(double(held), 2.5 * double(size)) << held;
    EXPECT_LT(double(held), 3.5 * double(size)) << held;
  }
}

// The volumes bake one after the other, so the bake's working set is its largest volume's. The
// sample's default bake refines the lamp's light into a volume of 8 times the grid's probes, whose
// own lines are quiet: the bake notes that volume's estimate as well, and it is the one within 2x
// of the peak the bake reports (the grid's alone falls under half of it).
TEST(MemoryCli, AMultiVolumeBakeNotesItsLargestVolume) {
  ScratchDir dir("memory_largest");
  const CliResult r = run_gibake_cli("bake " + kSample + " --ddgi --backend cpu --reconstruction-check off --out " +
                                     shell_quote(dir.path("probes.gibake")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string head = "memory: about ", tail = " MiB of host memory estimated for volume 1 (refined), the largest";
  const size_t at = r.err.find(tail);
  ASSERT_NE(at, std::string::npos) << r.err;
  const size_t start = r.err.rfind(head, at);
  ASSERT_NE(start, std::string::npos) << r.err;
  const double largest = std::stod(r.err.substr(start + head.size()));
  const double grid = std::stod(r.err.substr(r.err.find(head) + head.size()));
  const size_t peak_at = r.err.find("peak memory: ");
  ASSERT_NE(peak_at, std::string::npos) << r.err;
  const double peak = std::stod(r.err.substr(peak_at + 13));
  std::printf("grid %.0f MiB, largest volume %.0f MiB, peak %.0f MiB\n", grid, largest, peak);
  EXPECT_GT(largest, grid);
  EXPECT_GE(largest, 0.5 * peak);
  EXPECT_LE(largest, 2.0 * peak);
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
