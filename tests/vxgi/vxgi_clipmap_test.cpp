// Clipmaps (--vxgi-clipmaps K): layout, the coarsest equal to a single-volume bake, the
// cone tracer over all of them against the exact form factor, and the loader's checks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "tests/vxgi/emissive_square.h"
#include "tests/loader/test_util.h"
#include "tests/vxgi/vxgi_test_util.h"

namespace gibake {
namespace {

// An emissive square (10 cd/m^2, 1 m, facing down) 2 m above a black floor in a scene 12 m wide.
Scene square_scene() { return test::emissive_square_scene(0.f, 6.f); }

class VxgiClipmap : public ::testing::Test {
 protected:
  // Bakes the square scene as one volume (a) and as three clipmaps centred under the emitter (b).
  void bake_one_and_three(int resolution) {
    const VxgiSettings one = test::quick_settings(resolution, 4);
    three = one;
    three.clipmaps = 3;
    three.has_center = true;
    three.center = {0.f, 1.5f, 0.f};
    test::bake_vxgi_scene(square_scene(), one, a);
    test::bake_vxgi_scene(square_scene(), three, b);
  }
  VxgiSettings three;
  test::VxgiBake a, b;
};

TEST_F(VxgiClipmap, LayoutAndTheCoarsestEqualsOneVolume) {
  ASSERT_NO_FATAL_FAILURE(bake_one_and_three(24));
  const auto& v = b.file.vxgi_volumes();
  ASSERT_EQ(v.size(), 3u);
  // The coarsest is the single-volume bake, texel for texel (same voxelization, same ray keys).
  const gibake_vxgi_volume &c = v[2].desc(), &s = a.volume().desc();
  EXPECT_EQ(0, std::memcmp(c.grid_min, s.grid_min, sizeof c.grid_min));
  EXPECT_EQ(c.voxel_size, s.voxel_size);
  for (uint32_t l = 0; l < c.levels; ++l)
    for (uint32_t f = 0; f < 6; ++f)
      for (int32_t z = 0; z < v[2].level_dims(l)[2]; ++z)
        for (int32_t y = 0; y < v[2].level_dims(l)[1]; ++y)
          for (int32_t x = 0; x < v[2].level_dims(l)[0]; ++x)
            ASSERT_EQ(v[2].texel(l, f, x, y, z), a.volume().texel(l, f, x, y, z)) << l << " " << f;
  // Each finer one: half the voxel size, the same counts, centred on --vxgi-center within a voxel.
  for (int k = 0; k < 2; ++k) {
    const gibake_vxgi_volume& d = v[size_t(k)].desc();
    EXPECT_FLOAT_EQ(2.f * d.voxel_size, v[size_t(k) + 1].desc().voxel_size);
    for (int ax = 0; ax < 3; ++ax) {
      EXPECT_EQ(d.dims[ax], c.dims[ax]);
      const float mid = d.grid_min[ax] + 0.5f * float(d.dims[ax]) * d.voxel_size;
      EXPECT_NEAR(mid, three.center[size_t(ax)], d.voxel_size) << k << " axis " << ax;
    }
    EXPECT_EQ(d.clipmap_index, uint32_t(k));
    EXPECT_EQ(d.clipmap_count, 3u);
  }
}

// The emitter seen from below through three clipmaps against the exact irradiance, next to the
// coarsest alone: the fine clipmaps must keep the answer within the analytic test's band
// (0.6..1.45, vxgi_analytic_test.cpp says why) and, at 1 m, closer to exact than the coarse volume.
TEST_F(VxgiClipmap, EmissiveSquareThroughClipmaps) {
  ASSERT_NO_FATAL_FAILURE(bake_one_and_three(32));
  for (float h : {0.5f, 1.0f}) {
    const loader::Vec3 p{0, 2 - h, 0}, n{0, 1, 0};
    const double exact = test::square_irradiance(1.0, h, 10.0);
    const double coarse = loader::cone_trace_diffuse(a.volume(), p, n)[0] / exact;
    const double fine = loader::cone_trace_diffuse(b.file.vxgi_volumes(), p, n)[0] / exact;
    std::printf("emissive square at %.1f m: ratio to exact %.3f with one volume (%.3f m voxels), %.3f with 3 clipmaps\n",
                h, coarse, double(a.volume().desc().voxel_size), fine);
    EXPECT_GT(fine, 0.6) << h;
    EXPECT_LT(fine, 1.45) << h;
    if (h == 1.0f) {
      EXPECT_LT(std::fabs(fine - 1.0), std::fabs(coarse - 1.0));
    }
  }
  // A point outside the finest clipmaps (3 m to the side) is traced from the coarser ones.
  loader::Rgb e;
  ASSERT_TRUE(b.file.sample_vxgi({4.5f, 0.5f, 0}, {0, 1, 0}, e));
  EXPECT_GT(e[0], 0.f);
}

TEST_F(VxgiClipmap, LoaderRefusesClipmapsThatDoNotDouble) {
  const Scene scene = square_scene();
  VxgiSettings s = test::quick_settings(12, 1);
  s.clipmaps = 2;
  test::bake_vxgi_scene(scene, s, b);  // the fixture's b, unused otherwise here
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  std::vector<uint8_t> bytes = b.bytes;
  auto* d = reinterpret_cast<gibake_vxgi_volume*>(bytes.data() + test::table_entry(bytes, 0)->offset);
  ASSERT_EQ(d->clipmap_index, 0u);
  d->voxel_size *= 1.5f;
  test::reseal(bytes);
  loader::BakeFile file;
  const loader::Error e = file.open_borrowed(bytes.data(), bytes.size(), loader::LoadOptions{false});
  ASSERT_TRUE(bool(e));
  EXPECT_NE(e.message.find("twice the voxel size"), std::string::npos) << e.message;
}

TEST_F(VxgiClipmap, SettingsAreChecked) {
  VxgiSettings s;
  s.clipmaps = 9;
  EXPECT_EQ(validate_vxgi_settings(s).code(), ExitCode::BadArguments);
  s.clipmaps = 2;
  s.has_center = true;
  s.center = {0.f, NAN, 0.f};
  EXPECT_EQ(validate_vxgi_settings(s).code(), ExitCode::BadArguments);
}

}  // namespace
}  // namespace gibake
