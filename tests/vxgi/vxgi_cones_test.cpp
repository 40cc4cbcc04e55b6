// --vxgi-precompute-cones: the 16 cone-direction slices stored beside the six faces and
// the diffuse cone set along those 16 precomputed cone directions that reads them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/vxgi/emissive_square.h"
#include "tests/vxgi/vxgi_test_util.h"

namespace gibake {
namespace {

// The emitter over a grey floor 4 m wide.
Scene square_scene() { return test::emissive_square_scene(0.5f, 2.f); }

// Every stored slice texel, at every level, is sum_a d_a^2 x the face facing back at d on axis a,
// recomputed here from the stored faces (the file is f32, so to float rounding).
TEST(VxgiCones, SlicesAreTheWeightedFaces) {
  VxgiSettings s = test::quick_settings(16, 4);
  s.precompute_cones = true;
  test::VxgiBake b;
  test::bake_vxgi_scene(square_scene(), s, b);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  const loader::VxgiVolume& v = b.volume();
  ASSERT_EQ(v.faces(), 22u);
  const auto& dirs = loader::precomputed_cone_directions();
  size_t lit = 0;
  for (uint32_t l = 0; l < v.levels(); ++l) {
    const auto d = v.level_dims(l);
    for (uint32_t i = 0; i < 16; ++i)
      for (int32_t z = 0; z < d[2]; ++z)
        for (int32_t y = 0; y < d[1]; ++y)
          for (int32_t x = 0; x < d[0]; ++x) {
            loader::Rgba want{0, 0, 0, 0};
            for (int a = 0; a < 3; ++a) {
              const float da = dirs[i][size_t(a)];
              const loader::Rgba f = v.texel(l, uint32_t(2 * a + (da < 0.f ? 0 : 1)), x, y, z);
              for (int k = 0; k < 4; ++k) want[size_t(k)] += da * da * f[size_t(k)];
            }
            const loader::Rgba got = v.texel(l, 6 + i, x, y, z);
            for (int k = 0; k < 4; ++k) ASSERT_NEAR(got[size_t(k)], want[size_t(k)], 1e-5f * std::max(1.f, want[size_t(k)]));
            lit += got[0] > 0.f;
          }
  }
  EXPECT_GT(lit, 50u);
  // The six faces are what the bake without slices stores.
  test::VxgiBake plain;
  test::bake_vxgi_scene(square_scene(), test::quick_settings(16, 4), plain);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_EQ(plain.volume().faces(), 6u);
  for (uint32_t f = 0; f < 6; ++f) EXPECT_EQ(v.texel(1, f, 3, 2, 4), plain.volume().texel(1, f, 3, 2, 4));
}

// The 16 precomputed cone directions as a diffuse set: through the slices and through the three
// faces (a volume without slices) it gives the same irradiance within 5% (the slices skip only the
// per-face occlusion-aware blend), and against the emitter's exact irradiance it lies in the
// analytic band of vxgi_analytic_test.cpp (0.6..1.45), like the 60-degree set.
TEST(VxgiCones, PrecomputedConeSetReadsTheSlices) {
  VxgiSettings s = test::quick_settings(48, 4);
  s.precompute_cones = true;
  test::VxgiBake b, plain;
  test::bake_vxgi_scene(square_scene(), s, b);
  test::bake_vxgi_scene(square_scene(), test::quick_settings(48, 4), plain);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  loader::ConeOptions pre;
  pre.precomputed_cones = true;
  for (float h : {0.75f, 1.0f, 1.5f}) {
    const loader::Vec3 p{0, 2 - h, 0}, n{0, 1, 0};
    const double exact = test::square_irradiance(1.0, h, 10.0);
    const double sliced = loader::cone_trace_diffuse(b.volume(), p, n, pre)[0];
    const double faces = loader::cone_trace_diffuse(plain.volume(), p, n, pre)[0];
    const double six = loader::cone_trace_diffuse(plain.volume(), p, n)[0];
    std::printf("emissive square at %.2f m: 16-direction set %.3f (slices) %.3f (faces), 60-degree set %.3f; "
                "exact %.3f\n", h,
                sliced / exact, faces / exact, six / exact, 1.0);
    EXPECT_NEAR(sliced / faces, 1.0, 0.05) << h;
    EXPECT_GT(sliced / exact, 0.6) << h;
    EXPECT_LT(sliced / exact, 1.45) << h;
  }
}

// The deprecated names (ConeOptions::seed_cones, seed_diffuse_cones()) still select the same cones
// and directions, so engines written against them keep their output.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
TEST(VxgiCones, DeprecatedNamesSelectThePrecomputedCones) {
  VxgiSettings s = test::quick_settings(16, 4);
  s.precompute_cones = true;
  test::VxgiBake b;
  test::bake_vxgi_scene(square_scene(), s, b);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  loader::ConeOptions pre, old;
  pre.precomputed_cones = true;
  old.seed_cones = true;
  const loader::Vec3 p{0, 1, 0}, n{0.3f, 1, 0.2f};
  const loader::Rgb a = loader::cone_trace_diffuse(b.volume(), p, n, pre);
  const loader::Rgb c = loader::cone_trace_diffuse(b.volume(), p, n, old);
  const loader::Rgb six = loader::cone_trace_diffuse(b.volume(), p, n);
  EXPECT_GT(a[0], 0.f);
  EXPECT_NE(a[0], six[0]);  // the two sets differ, so equality below means the same set
  for (int k = 0; k < 3; ++k) EXPECT_EQ(a[size_t(k)], c[size_t(k)]) << k;
  EXPECT_EQ(&loader::seed_diffuse_cones(), &loader::precomputed_cone_directions());
}
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

}  // namespace
}  // namespace gibake
