// The voxel-GI bake end to end on scenes built in code: a furnace (a closed emissive box, where
// every cone must return the walls' radiance), opacity inside closed solids at every mip, and
// determinism across thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "tests/bake/scene_builders.h"
#include "tests/vxgi/vxgi_test_util.h"

namespace gibake {
namespace {

constexpr float kPi = 3.14159265358979f;

// Inside a closed box whose walls emit Le = 1 cd/m^2 and reflect nothing, the radiance from every
// direction is Le, so irradiance is pi Le for any normal (the cone set's weights sum to pi).
TEST(VxgiBake, FurnaceBoxGivesPiLe) {
  Scene scene;
  const int wall = test::add_material(scene, 0.f, 1.f);
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, true, wall);
  VxgiSettings s;
  s.resolution = std::getenv("RES") ? std::atoi(std::getenv("RES")) : 24;
  s.rays = 8;
  s.bounces = 0;
  test::VxgiBake bake;
  test::bake_vxgi_scene(scene, s, bake);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  const loader::VxgiVolume& v = bake.volume();
  const loader::Vec3 normals[] = {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}, {0.577f, 0.577f, 0.577f}};
  const loader::Vec3 points[] = {{0, 0, 0}, {0.5f, -0.3f, 0.2f}, {-0.6f, 0.6f, 0.6f}};
  for (const loader::Vec3& p : points)
    for (const loader::Vec3& n : normals) {
      const loader::Rgb e = loader::cone_trace_diffuse(v, p, n);
      std::printf("furnace p (%.1f %.1f %.1f) n (%.2f %.2f %.2f): E %.4f (pi %.4f)\n", p[0], p[1], p[2], n[0], n[1],
                  n[2], e[0], kPi);
      EXPECT_NEAR(e[0], kPi, 0.05f * kPi);
    }
}

}  // namespace
}  // namespace gibake
namespace gibake {
TEST(VxgiDebug, Cones) {
  Scene scene;
  const int wall = test::add_material(scene, 0.f, 1.f);
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, true, wall);
  VxgiSettings s;
  s.resolution = 24;
  s.rays = 8;
  s.bounces = 0;
  test::VxgiBake bake;
  test::bake_vxgi_scene(scene, s, bake);
  const loader::VxgiVolume& v = bake.volume();
  for (float ap : {0.05f, 0.3f, 1.0472f}) {
    for (loader::Vec3 d : {loader::Vec3{0, 1, 0}, loader::Vec3{0.707f, 0.707f, 0}, loader::Vec3{0.577f, 0.577f, 0.577f}}) {
      loader::ConeOptions o; o.use_sdf = false; o.step_scale = std::getenv("STEP") ? std::atof(std::getenv("STEP")) : 1.f;
      const loader::ConeResult r = loader::cone_trace(v, {0, 0, 0}, {0, 1, 0}, d, ap, o);
      std::printf("ap %.2f d (%.2f %.2f %.2f): L %.3f a %.3f steps %u\n", ap, d[0], d[1], d[2], r.radiance[0], r.alpha, r.steps);
    }
  }
  // dump a column of level 0 along y at x=z=centre
  auto dims = v.level_dims(0);
  for (int y = 0; y < dims[1]; ++y) {
    auto t = v.texel(0, 3, dims[0] / 2, y, dims[2] / 2);
    auto t2 = v.texel(0, 2, dims[0] / 2, y, dims[2] / 2);
    auto t3 = v.texel(0, 0, dims[0] / 2, y, dims[2] / 2);
    std::printf("y %d: -Y %.2f %.2f  +Y %.2f %.2f +X %.2f %.2f\n", y, t[0], t[3], t2[0], t2[3], t3[0], t3[3]);
  }
}
}
