// The CLI end to end: gibake bake --vxgi, info, verify (--against), sample (CSV, JSON, points
// outside, bad input) and the refusal of absurd sizes, with the documented exit codes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/loader/test_util.h"

namespace gibake {
namespace {

const std::string kScene = std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/cornell_blocks.gltf";
const char* kSmall = " --vxgi --vxgi-res 16 --vxgi-rays 4 --vxgi-bounces 1 --vxgi-calibrate 16";

class VxgiCli : public ::testing::Test {
 protected:
  void SetUp() override { dir = test::scratch_dir("vxgi_cli"); }
  void TearDown() override { std::filesystem::remove_all(dir); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir + "/" + name) << text; }
  // Bakes the small scene with `extra` options to `out` and opens it into `file`.
  void bake_small(const std::string& extra, const std::string& out, loader::BakeFile& file) {
    const test::RunResult r = test::run_gibake(kScene + kSmall + extra + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.out;
    ASSERT_FALSE(file.open(out));
  }
  // `gibake sample --backend vulkan` (lavapipe) against the CPU on a bake with these sides.
  void SampleOnVulkan(const std::string& sides);
  std::string dir;
};

TEST_F(VxgiCli, BakeInfoVerifySample) {
  const std::string out = dir + "/cb.gibake";
  test::RunResult r = test::run_gibake(kScene + kSmall + " --out " + out + " --progress lines");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("MiB of memory"), std::string::npos) << r.out;  // the estimate, before allocation
  loader::BakeFile file;
  ASSERT_FALSE(file.open(out));
  EXPECT_EQ(file.header().version_minor, GIBAKE_VERSION_MINOR_VXGI);
  ASSERT_EQ(file.vxgi_volumes().size(), 1u);
  EXPECT_EQ(file.vxgi_volumes()[0].radiance_format(), uint32_t(GIBAKE_FORMAT_RGBA16F));
  EXPECT_TRUE(file.vxgi_volumes()[0].has_sdf());

  r = test::run_gibake_stdout("info " + out + " --format json");
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("\"vxgi\""), std::string::npos);
  EXPECT_NE(r.out.find("vxgi_radiance"), std::string::npos);
  r = test::run_gibake("verify " + out + " --against " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("against.vxgi[0].radiance"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("pass  against.vxgi[0].sdf: max abs 0.000000 m"), std::string::npos) << r.out;
  // The distance field is compared too: the cone tracer steps by it. In one file only, it differs.
  const std::string no_sdf = dir + "/cb_nosdf.gibake";
  ASSERT_EQ(test::run_gibake(kScene + kSmall + " --vxgi-sdf off --out " + no_sdf).exit_code, 0);
  r = test::run_gibake("verify " + no_sdf + " --against " + out);
  EXPECT_EQ(r.exit_code, 7) << r.out;
  EXPECT_NE(r.out.find("fail  against.vxgi[0].sdf: the distance field is in the reference but not in this file"),
            std::string::npos)
      << r.out;

  // preview lights a view with probes or cascades; a file of voxel GI alone is the wrong file for
  // it (exit 1), not a bad one.
  r = test::run_gibake("preview " + kScene + " --bake " + out + " --size 32x32 --out " + dir + "/v.png");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("--bake: the bake file holds neither DDGI probes nor LPV cascades"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/v.png"));

  // VDB grids for eyes: level 0's faces and alpha.
  r = test::run_gibake("export " + out + " --vdb " + dir + "/cb.vdb");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_GT(std::filesystem::file_size(dir + "/cb.vdb"), 1000u);
  const std::vector<uint8_t> vdb = test::read_bytes(dir + "/cb.vdb");
  const std::string text(vdb.begin(), vdb.end());
  for (const char* name : {"vxgi0_px", "vxgi0_nz", "vxgi0_alpha"}) EXPECT_NE(text.find(name), std::string::npos) << name;

  // Another seed: the radiance differs, verify --against says so (exit 7).
  const std::string other = dir + "/cb7.gibake";
  ASSERT_EQ(test::run_gibake(kScene + kSmall + " --seed 7 --out " + other).exit_code, 0);
  r = test::run_gibake("verify " + other + " --against " + out + " --tolerance 1e-6");
  EXPECT_EQ(r.exit_code, 7) << r.out;

  write("pts.csv", "# x,y,z,nx,ny,nz\n0,1,0,0,1,0\n0.5,0.5,0.5, 0,0,2\n\n50,50,50,1,0,0  # outside\n");
  r = test::run_gibake_stdout("sample " + out + " --points " + dir + "/pts.csv --source vxgi");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::istringstream lines(r.out);
  std::string l1, l2, l3;
  std::getline(lines, l1);
  std::getline(lines, l2);
  std::getline(lines, l3);
  EXPECT_EQ(l1.rfind("0,1,0,0,1,0,", 0), 0u) << l1;
  EXPECT_EQ(l2.rfind("0.5,0.5,0.5,0,0,1,", 0), 0u) << l2;  // normal normalised
  EXPECT_EQ(l3, "50,50,50,1,0,0,,,");
  loader::Rgb e;
  ASSERT_TRUE(file.sample_vxgi({0, 1, 0}, {0, 1, 0}, e));
  EXPECT_GT(e[0], 0.f);
  r = test::run_gibake("sample " + out + " --points " + dir + "/pts.csv --source vxgi --format json");
  EXPECT_NE(r.out.find("\"r\":null"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 of 3 points lie outside every vxgi volume"), std::string::npos) << r.out;
  // The file has no DDGI volume: bad argument, one line.
  r = test::run_gibake("sample " + out + " --points " + dir + "/pts.csv --source ddgi");
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("gibake: error: " + out + ": --source: the bake file has no DDGI volume"), std::string::npos) << r.out;
}

// --source ddgi and lpv print exactly what the loader's samplers return (9 significant digits),
// and points outside the probe cells / cascades get empty values.
// Options that act only with another are refused without it, as is a clipmap centre outside the
// scene (its finer clipmaps would hold nothing; far enough out, past the voxel indices), and voxel
// GI with shards, which do not carry it: each with exit 1 and its option named, no file written.
TEST_F(VxgiCli, SettingsThatCouldNotActAreRefused) {
  const std::string out = dir + "/refused.gibake";
  const std::pair<std::string, std::string> cases[] = {
      {" --vxgi-align-walls 3", "--vxgi-align-walls: only with --vxgi-sides split and one clipmap"},
      {" --vxgi-sides split --vxgi-clipmaps 2 --vxgi-align-walls 3", "--vxgi-align-walls: only with"},
      {" --vxgi-center 0,1,0", "--vxgi-center: centres the finer clipmaps: only with --vxgi-clipmaps 2 or more"},
      {" --vxgi-clipmaps 2 --vxgi-center 1e9,0,0", "--vxgi-center: 1e+09,0,0 lies outside the scene's voxel box"},
      {" --ddgi --shard 0/2", "--shard: voxel GI is not carried by shards"},
      {" --ddgi --from-shards " + dir + "/part_0.gibake", "--from-shards: voxel GI is not carried by shards"}};
  for (const auto& [extra, line] : cases) {
    const test::RunResult r = test::run_gibake(kScene + kSmall + extra + " --out " + out);
    EXPECT_EQ(r.exit_code, 1) << extra << "\n" << r.out;
    EXPECT_NE(r.out.find("gibake: error: " + line), std::string::npos) << extra << "\n" << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(VxgiCli, SampleDdgiAndLpvMatchTheLoader) {
  const std::string out = dir + "/dl.gibake";
  ASSERT_EQ(test::run_gibake(kScene + " --ddgi --lpv --probe-counts 3,3,3 --rays 32 --lpv-res 8 --lpv-samples 4096 --out " + out)
                .exit_code, 0);
  loader::BakeFile file;
  ASSERT_FALSE(file.open(out));
  write("pts.csv", "0.1,0.5,-0.2,0,1,0\n-0.3,1.2,0.4,1,0,0\n9,9,9,0,0,1\n");
  const loader::Vec3 p[2] = {{0.1f, 0.5f, -0.2f}, {-0.3f, 1.2f, 0.4f}}, n[2] = {{0, 1, 0}, {1, 0, 0}};
  for (const char* source : {"ddgi", "lpv"}) {
    const test::RunResult r = test::run_gibake_stdout("sample " + out + " --points " + dir + "/pts.csv --source " + source);
    ASSERT_EQ(r.exit_code, 0) << r.out;
    std::istringstream lines(r.out);
    for (int i = 0; i < 2; ++i) {
      std::string line;
      std::getline(lines, line);
      std::vector<float> v;
      std::stringstream ss(line);
      for (std::string f; std::getline(ss, f, ',');) v.push_back(std::stof(f));
      ASSERT_EQ(v.size(), 9u) << line;
      const loader::Rgb e = std::string(source) == "ddgi" ? file.ddgi_volumes()[0].sample_irradiance(p[i], n[i])
                                                          : file.sample_lpv(p[i], n[i]);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[size_t(6 + c)], e[size_t(c)], 1e-6f * std::max(1.f, e[size_t(c)])) << source;
      EXPECT_GT(e[0], 0.f) << source;
    }
    std::string last;
    std::getline(lines, last);
    EXPECT_EQ(last, "9,9,9,0,0,1,,,") << source;
  }
}

TEST_F(VxgiCli, SampleRejectsBadPoints) {
  const std::string out = dir + "/cb.gibake";
  ASSERT_EQ(test::run_gibake(kScene + " --vxgi --vxgi-res 12 --vxgi-rays 2 --vxgi-calibrate 0 --out " + out).exit_code, 0);
  write("bad.csv", "0,1,0,0,1,0\n0,1,zero,0,1,0\n");
  test::RunResult r = test::run_gibake("sample " + out + " --points " + dir + "/bad.csv --source vxgi");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.out, "gibake: error: " + dir + "/bad.csv: line 2: field 3 is not a finite number\n");
  write("zero.csv", "0,1,0,0,0,0\n");
  r = test::run_gibake("sample " + out + " --points " + dir + "/zero.csv --source vxgi");
  EXPECT_EQ(r.exit_code, 3);
  r = test::run_gibake("sample " + out + " --points " + dir + "/missing.csv --source vxgi");
  EXPECT_EQ(r.exit_code, 2);
}

TEST_F(VxgiCli, RefusesAbsurdResolutionBeforeWriting) {
  const std::string out = dir + "/big.gibake";
  test::RunResult r = test::run_gibake(kScene + " --vxgi --vxgi-res 4000 --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("TiB, more than the 16 GiB of --max-memory"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(out));
  r = test::run_gibake(kScene + " --vxgi --vxgi-rays 0 --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  // The range --help gives is the one judged, before the import: the padding's three voxels
  // (a voxel each side and one more) within the format's 4096 an axis; the value is repeated.
  r = test::run_gibake(kScene + " --vxgi --vxgi-res 4094 --progress lines --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("--vxgi-res: must be between 4 and 4093, got 4094"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("import"), std::string::npos) << r.out;
  r = test::run_gibake(kScene + " --vxgi --vxgi-clipmaps 9 --out " + out);
  EXPECT_NE(r.out.find("must be between 1 and 8, got 9"), std::string::npos) << r.out;
  // Where the clipmaps' count makes the cost (the finest voxelizes the whole scene), it is named.
  r = test::run_gibake(kScene + " --vxgi --vxgi-res 16 --vxgi-clipmaps 7 --max-memory 1G --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("gibake: error: --vxgi-clipmaps: 7 clipmaps of "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("lower --vxgi-res or --vxgi-clipmaps, or raise --max-memory"), std::string::npos) << r.out;
  // Beside a probe bake the refusal comes right after the import, before the probes are placed.
  r = test::run_gibake(kScene + " --ddgi --vxgi --vxgi-res 4000 --progress lines --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("TiB, more than the 16 GiB of --max-memory"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("probe grid"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// gibake sample --backend vulkan (the GLSL include on a device) prints what the CPU tracer prints,
// within 1e-4 relative (lavapipe matches to 1e-6, tests/vulkan/gpu_vxgi_test.cpp); skipped without
// lavapipe (exit 4). --timing reports the query time on stderr.
TEST_F(VxgiCli, SampleOnVulkanMatchesTheCpu) {
  for (const char* sides : {"mixed", "split"}) SampleOnVulkan(sides);
}

void VxgiCli::SampleOnVulkan(const std::string& sides) {
  SCOPED_TRACE("--vxgi-sides " + sides);
  const std::string out = dir + "/cb.gibake";
  ASSERT_EQ(test::run_gibake(kScene + kSmall + " --vxgi-sides " + sides + " --out " + out).exit_code, 0);
  std::string pts;
  for (int i = 0; i < 40; ++i)
    pts += std::to_string(-0.9 + 0.045 * i) + "," + std::to_string(0.1 + 0.04 * i) + ",0.2," + std::to_string(i % 3 - 1) +
           ",1," + std::to_string(i % 2) + "\n";
  write("pts.csv", pts);
  const test::RunResult cpu = test::run_gibake_stdout("sample " + out + " --points " + dir + "/pts.csv --source vxgi");
  ASSERT_EQ(cpu.exit_code, 0) << cpu.out;
  const test::RunResult gpu = test::run_gibake_stdout("sample " + out + " --points " + dir +
                                                      "/pts.csv --source vxgi --backend vulkan --vulkan-device lavapipe");
  if (gpu.exit_code == 4) GTEST_SKIP() << "no lavapipe: " << gpu.out;
  ASSERT_EQ(gpu.exit_code, 0) << gpu.out;
  std::istringstream a(cpu.out), b(gpu.out);
  size_t lines = 0;
  for (std::string la, lb; std::getline(a, la) && std::getline(b, lb); ++lines) {
    std::stringstream sa(la), sb(lb);
    for (std::string fa, fb; std::getline(sa, fa, ',') && std::getline(sb, fb, ',');) {
      const double x = std::stod(fa), y = std::stod(fb);
      EXPECT_NEAR(x, y, 1e-4 * std::max(1.0, std::fabs(x))) << la << " | " << lb;
    }
  }
  EXPECT_EQ(lines, 40u);
  const test::RunResult timed = test::run_gibake("sample " + out + " --points " + dir + "/pts.csv --source vxgi --timing");
  EXPECT_NE(timed.out.find("vxgi queries on the CPU"), std::string::npos) << timed.out;
  EXPECT_EQ(test::run_gibake("sample " + out + " --points " + dir + "/pts.csv --source ddgi --backend vulkan").exit_code, 1);
}

// --vxgi-precompute-cones: 22 faces in the file, info says so, verify --against compares them.
TEST_F(VxgiCli, PrecomputedCones) {
  const std::string out = dir + "/pc.gibake";
  loader::BakeFile file;
  ASSERT_NO_FATAL_FAILURE(bake_small(" --vxgi-precompute-cones", out, file));
  EXPECT_EQ(file.vxgi_volumes()[0].faces(), 22u);
  test::RunResult r = test::run_gibake_stdout("info " + out);
  EXPECT_NE(r.out.find("16 precomputed cone slices"), std::string::npos) << r.out;
  r = test::run_gibake("verify " + out + " --against " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out;
}

// --vxgi-sides split (and --vxgi-align-walls): a valid file that verify accepts and whose
// settings say so; anything but mixed|split, or a level beyond 6, is refused (exit 1) naming the option.
TEST_F(VxgiCli, SplitSides) {
  const std::string out = dir + "/split.gibake";
  loader::BakeFile file;
  ASSERT_NO_FATAL_FAILURE(bake_small(" --vxgi-sides split", out, file));
  test::RunResult r = test::run_gibake("verify " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  r = test::run_gibake_stdout("info " + out);
  EXPECT_NE(r.out.find("split_sides"), std::string::npos) << r.out;
  r = test::run_gibake(kScene + kSmall + " --vxgi-sides both --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("--vxgi-sides"), std::string::npos) << r.out;
  ASSERT_NO_FATAL_FAILURE(bake_small(" --vxgi-sides split --vxgi-align-walls 3", out, file));
  r = test::run_gibake(kScene + kSmall + " --vxgi-sides split --vxgi-align-walls 7 --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("--vxgi-align-walls"), std::string::npos) << r.out;
}

// --vxgi-clipmaps / --vxgi-center: the file holds K volumes, info lists them, verify --against
// compares each, sample traces through them; a bad centre or count is refused (exit 1), and the
// memory refusal counts every clipmap and the finest voxelization (res 1024, 4 clipmaps: 8192 on
// the longest axis while the voxelizer works).
TEST_F(VxgiCli, Clipmaps) {
  const std::string out = dir + "/cm.gibake";
  loader::BakeFile file;
  ASSERT_NO_FATAL_FAILURE(bake_small(" --vxgi-clipmaps 2 --vxgi-center 0,0.8,0", out, file));
  ASSERT_EQ(file.vxgi_volumes().size(), 2u);
  EXPECT_FLOAT_EQ(2.f * file.vxgi_volumes()[0].desc().voxel_size, file.vxgi_volumes()[1].desc().voxel_size);
  test::RunResult r = test::run_gibake_stdout("info " + out);
  EXPECT_NE(r.out.find("vxgi volume 1"), std::string::npos) << r.out;
  r = test::run_gibake("verify " + out + " --against " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("against.vxgi[1].radiance"), std::string::npos) << r.out;
  write("pts.csv", "0,1,0,0,1,0\n");
  r = test::run_gibake_stdout("sample " + out + " --points " + dir + "/pts.csv --source vxgi");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(r.out.rfind("0,1,0,0,1,0,", 0), 0u) << r.out;
  EXPECT_EQ(test::run_gibake(kScene + kSmall + " --vxgi-clipmaps 9 --out " + out).exit_code, 1);
  r = test::run_gibake(kScene + kSmall + " --vxgi-clipmaps 2 --vxgi-center 0,x,0 --out " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("--vxgi-center"), std::string::npos) << r.out;
  r = test::run_gibake(kScene + " --vxgi --vxgi-res 1024 --vxgi-clipmaps 4 --out " + dir + "/big.gibake");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("more than the 16 GiB of --max-memory"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace gibake
