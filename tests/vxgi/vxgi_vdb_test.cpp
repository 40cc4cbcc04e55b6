// `gibake bake --vxgi --voxels scene.vdb`: the .vdb holds, beside the voxel grids, the voxel-GI
// grids vxgi0_px .. vxgi0_nz and vxgi0_alpha (io/export/voxels_vdb.h). Checked against the bake
// file the same run writes, read with the loader: every voxel of every face, radiance = rgb / alpha
// of the stored texel (RGBA16F in the file, float in the VDB: 2e-3 relative covers f16 rounding),
// and the transform puts index (i,j,k) at that voxel's centre.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "tests/loader/test_util.h"

namespace gibake {
namespace {

const std::string kScene = std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/cornell_blocks.gltf";

TEST(VxgiVdb, VoxelsFileHoldsTheVoxelGiGrids) {
  const std::string dir = test::scratch_dir("vxgi_vdb");
  const std::string out = dir + "/cb.gibake", vdb = dir + "/cb.vdb";
  const test::RunResult r = test::run_gibake(kScene + " --vxgi --vxgi-res 16 --vxgi-rays 4 --vxgi-bounces 1 "
                                             "--vxgi-calibrate 0 --voxels " + vdb + " --voxel-res 32 --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  loader::BakeFile file;
  ASSERT_FALSE(file.open(out));
  ASSERT_EQ(file.vxgi_volumes().size(), 1u);
  const loader::VxgiVolume& v = file.vxgi_volumes()[0];
  const gibake_vxgi_volume& d = v.desc();
  openvdb::initialize();
  openvdb::io::File f(vdb);
  f.open();
  openvdb::GridPtrVecPtr grids = f.getGrids();
  f.close();
  auto find = [&](const std::string& n) { return openvdb::findGridByName(*grids, n); };
  ASSERT_TRUE(find("density"));  // the voxel grids are still there
  auto alpha = openvdb::gridPtrCast<openvdb::FloatGrid>(find("vxgi0_alpha"));
  ASSERT_TRUE(alpha);
  const openvdb::Vec3d c0 = alpha->transform().indexToWorld(openvdb::Coord(0, 0, 0));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(c0[a], d.grid_min[a] + 0.5 * d.voxel_size, 1e-5);
  const char* names[6] = {"vxgi0_px", "vxgi0_nx", "vxgi0_py", "vxgi0_ny", "vxgi0_pz", "vxgi0_nz"};
  size_t lit = 0, checked = 0;
  for (uint32_t face = 0; face < 6; ++face) {
    auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find(names[face]));
    ASSERT_TRUE(g) << names[face];
    auto acc = g->getConstAccessor();
    auto aacc = alpha->getConstAccessor();
    for (int32_t z = 0; z < d.dims[2]; ++z)
      for (int32_t y = 0; y < d.dims[1]; ++y)
        for (int32_t x = 0; x < d.dims[0]; ++x) {
          const loader::Rgba t = v.texel(0, face, x, y, z);
          const openvdb::Coord ijk(x, y, z);
          const openvdb::Vec3s got = acc.getValue(ijk);
          ++checked;
          if (!(t[3] > 0.f)) {
            EXPECT_EQ(got, openvdb::Vec3s(0.f)) << names[face] << " " << x << "," << y << "," << z;
            continue;
          }
          EXPECT_GE(aacc.getValue(ijk), t[3] - 2e-3f);
          for (int c = 0; c < 3; ++c) {
            const float want = t[size_t(c)] / t[3];
            EXPECT_NEAR(got[c], want, 2e-3f * std::max(1.f, std::fabs(want))) << names[face] << " channel " << c;
          }
          lit += t[0] > 0.f;
        }
  }
  EXPECT_EQ(checked, size_t(6) * size_t(d.dims[0]) * size_t(d.dims[1]) * size_t(d.dims[2]));
  EXPECT_GT(lit, 100u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gibake
