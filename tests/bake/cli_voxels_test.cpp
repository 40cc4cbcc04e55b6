// `gibake scene.gltf --voxels out.vdb` end to end: alone and with --ddgi, exit codes, the file.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

int run(const std::string& args) { return gibake::test::run_gibake_cli(args).exit_code; }

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

const std::string kCornell = std::string(GIBAKE_ASSETS_DIR) + "/cornell-box-nvpro/cornellBox.gltf";

std::filesystem::path scratch() {
  const auto dir = gibake::test::process_tmp() / "voxel_cli";
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(VoxelCli, VoxelsAloneAndWithDdgi) {
  const auto dir = scratch();
  const std::string vdb = (dir / "cornell.vdb").string(), probes = (dir / "cornell.gibake").string();
  ASSERT_EQ(run(kCornell + " --voxels " + vdb + " --voxel-res 48 --sun 0.2,-1,0.1:1000"), 0);
  openvdb::initialize();
  openvdb::io::File f(vdb);
  f.open();
  auto grids = f.readAllGridMetadata();
  f.close();
  size_t named = 0;
  for (const auto& g : *grids)
    for (const char* n : {"density", "albedo", "emission", "normal", "direct", "sdf", "interior", "aniso_pz"})
      named += g->getName() == n;
  EXPECT_EQ(named, 8u);
  std::filesystem::remove(vdb);
  ASSERT_EQ(run(kCornell + " --ddgi --out " + probes + " --probe-counts 2,2,2 --rays 32 --bounces 1 --voxels " + vdb +
                " --voxel-size 0.2 --progress json"),
            0);
  EXPECT_TRUE(std::filesystem::exists(vdb));
  EXPECT_TRUE(std::filesystem::exists(probes));
  std::filesystem::remove_all(dir);
}

// OpenVDB writes a random UUID into every file's header; the bake's outputs are the same bytes for
// the same inputs, so the UUID is derived from the content, and OpenVDB still reads the file.
TEST(VoxelCli, TheSameBytesEveryRun) {
  const auto dir = scratch();
  const std::string a = (dir / "a.vdb").string(), b = (dir / "b.vdb").string();
  ASSERT_EQ(run(kCornell + " --voxels " + a + " --voxel-res 16 --threads 1"), 0);
  ASSERT_EQ(run(kCornell + " --voxels " + b + " --voxel-res 16 --threads 2"), 0);
  EXPECT_EQ(file_bytes(a), file_bytes(b));
  openvdb::initialize();
  openvdb::io::File f(a);
  f.open();
  EXPECT_EQ(f.getUniqueTag().size(), 36u);
  EXPECT_EQ(f.getUniqueTag()[14], '5');  // a name-based UUID
  EXPECT_FALSE(f.readAllGridMetadata()->empty());
  f.close();
  std::filesystem::remove_all(dir);
}

TEST(VoxelCli, BadArguments) {
  const auto dir = scratch();
  const std::string vdb = (dir / "x.vdb").string();
  EXPECT_EQ(run(kCornell + " --voxels " + vdb + " --voxel-size 0.1 --voxel-res 64"), 1);  // both
  EXPECT_EQ(run(kCornell + " --voxels " + vdb + " --voxel-size 0.00001"), 1);           // over the memory cap
  EXPECT_EQ(run(kCornell + " --voxels " + vdb + " --voxel-res 0"), 1);
  EXPECT_EQ(run(kCornell + " --voxels " + vdb + " --out " + (dir / "p.bin").string()), 1);  // --out needs --ddgi
  EXPECT_EQ(run(kCornell), 1);                                                             // nothing to bake
  EXPECT_EQ(run(kCornell + " --voxels " + (dir / "missing" / "x.vdb").string()), 2);
  EXPECT_EQ(run(kCornell + " --voxels " + kCornell), 1);  // never over an input: an argument mistake
  EXPECT_FALSE(std::filesystem::exists(vdb));
  std::filesystem::remove_all(dir);
}

}  // namespace

// OpenVDB is a module gibake loads when a command writes VDB or needs its distances
// (io/vdb/vdb_module.h): linked into the executable, its symbol bindings would slow every command's
// start. The executable must not need it; a --voxels bake (above) loads it.
TEST(VoxelCli, TheExecutableDoesNotLinkOpenVdb) {
  const std::string cmd = "readelf -d " + gibake::test::shell_quote(GIBAKE_EXE) + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string dynamic;
  char buffer[4096];
  for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) dynamic.append(buffer, n);
  ASSERT_EQ(pclose(pipe), 0) << dynamic;
  ASSERT_NE(dynamic.find("(NEEDED)"), std::string::npos) << dynamic;  // readelf ran and listed libraries
  EXPECT_EQ(dynamic.find("libopenvdb"), std::string::npos) << dynamic;
}
