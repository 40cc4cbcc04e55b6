// `gibake export`: EXR images and the VDB grid file are written (atomically) and readable.
#include <OpenEXR/ImfArray.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include "io/bakefile/bake_file.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;

bool has_prefix(const std::vector<uint8_t>& bytes, const std::vector<uint8_t>& prefix) {
  return bytes.size() >= prefix.size() && std::equal(prefix.begin(), prefix.end(), bytes.begin());
}

TEST(ExportCli, WritesExrAndVdb) {
  const std::string dir = test::scratch_dir("export");
  const DdgiResult r = test::make_ddgi(3, 2, 2, 2, 41);
  BakeOutputs outputs;
  outputs.ddgi = &r;
  ASSERT_TRUE(write_bake_file(dir + "/probes.bin", outputs, BakeFileOptions{}, {}).is_ok());
  const test::RunResult run =
      test::run_gibake("export " + dir + "/probes.bin --exr " + dir + "/exr --vdb " + dir + "/probes.vdb");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const std::vector<uint8_t> exr_magic{0x76, 0x2f, 0x31, 0x01};
  for (const char* name : {"irradiance.exr", "depth.exr", "sh.exr"}) {
    const std::vector<uint8_t> bytes = test::read_bytes(dir + "/exr/" + name);
    EXPECT_TRUE(has_prefix(bytes, exr_magic)) << name;
  }
  const std::vector<uint8_t> vdb = test::read_bytes(dir + "/probes.vdb");
  EXPECT_TRUE(has_prefix(vdb, {0x20, 0x42, 0x44, 0x56})) << "VDB magic";
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  // Read back: the SH image holds the coefficients, the VDB grids the L0 irradiance at the
  // probes' world positions.
  Imf::InputFile exr((dir + "/exr/sh.exr").c_str());
  const Imath::Box2i window = exr.header().dataWindow();
  const int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
  ASSERT_EQ(width, 6);
  ASSERT_EQ(height, 2);
  std::vector<float> c4g(size_t(width) * height);
  Imf::FrameBuffer frame;
  frame.insert("c4.G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(c4g.data()), sizeof(float), sizeof(float) * width));
  exr.setFrameBuffer(frame);
  exr.readPixels(window.min.y, window.max.y);
  // probe (x=2, y=1, z=1): index 2 + 3*(1 + 2*1) = 11, pixel (2 + 3*1, 1)
  EXPECT_EQ(c4g[size_t(1) * width + 5], r.sh[(11 * 9 + 4) * 3 + 1]);

  openvdb::initialize();
  openvdb::io::File file(dir + "/probes.vdb");
  file.open();
  auto grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("irradiance_l0"));
  auto state = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("state"));
  file.close();
  ASSERT_TRUE(grid && state);
  const openvdb::Vec3d world = grid->transform().indexToWorld(openvdb::Coord(2, 1, 1));
  EXPECT_NEAR(world.x(), -1.0 + 2 * 1.5, 1e-6);
  EXPECT_NEAR(world.y(), 0.0 + 1 * 1.0, 1e-6);
  EXPECT_NEAR(world.z(), -2.0 + 1 * 2.0, 1e-6);
  const openvdb::Vec3s l0 = grid->getConstAccessor().getValue(openvdb::Coord(2, 1, 1));
  EXPECT_NEAR(l0.x(), 3.14159265f * 0.282095f * r.sh[(11 * 9) * 3], 1e-4f);
  EXPECT_EQ(state->getConstAccessor().getValue(openvdb::Coord(4 % 3, (4 / 3) % 2, 4 / 6)), 1.f);  // probe 4 inactive

  EXPECT_EQ(test::run_gibake("export " + dir + "/probes.bin").exit_code, 1);  // neither --exr nor --vdb
  EXPECT_EQ(test::run_gibake("export " + dir + "/probes.bin --vdb " + dir + "/missing/x.vdb").exit_code, 2);
  std::filesystem::remove_all(dir);
}

TEST(ExportCli, VdbHoldsLpvCascades) {
  const std::string dir = test::scratch_dir("export_lpv");
  const DdgiResult r = test::make_ddgi(2, 2, 2, 1, 5, false);
  const LpvResult lpv = test::make_lpv(3, 2, 4, 2, 8);
  BakeOutputs outputs;
  outputs.ddgi = &r;
  outputs.lpv = &lpv;
  ASSERT_TRUE(write_bake_file(dir + "/lpv.bin", outputs, BakeFileOptions{}, {}).is_ok());
  const test::RunResult run = test::run_gibake("export " + dir + "/lpv.bin --vdb " + dir + "/lpv.vdb");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  openvdb::initialize();
  openvdb::io::File file(dir + "/lpv.vdb");
  file.open();
  auto sh0 = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("lpv1_g_sh0"));
  auto sh1 = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("lpv1_g_sh1"));
  ASSERT_TRUE(sh0 && sh1);
  // Cell (2,1,3) of cascade 1: the voxel's world position is the cell centre.
  const LpvCascade& c = lpv.cascades[1];
  const size_t i = 2 + 3 * (1 + 2 * 3);
  const openvdb::Vec3d world = sh0->transform().indexToWorld(openvdb::Coord(2, 1, 3));
  EXPECT_NEAR(world.x(), c.grid_min[0] + 2.5 * c.cell_size, 1e-5);
  EXPECT_NEAR(world.z(), c.grid_min[2] + 3.5 * c.cell_size, 1e-5);
  EXPECT_EQ(sh0->getConstAccessor().getValue(openvdb::Coord(2, 1, 3)), c.sh[i * 12 + 4]);
  const openvdb::Vec3s v = sh1->getConstAccessor().getValue(openvdb::Coord(2, 1, 3));
  EXPECT_EQ(v.x(), c.sh[i * 12 + 4 + 3]);
  EXPECT_EQ(v.y(), c.sh[i * 12 + 4 + 1]);
  file.close();
  std::filesystem::remove_all(dir);
}

}  // namespace
