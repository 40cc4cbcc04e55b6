// The GLSL cone tracer engines include (kernels/shaders/vxgi_cone.glsl, run by vxgi_diffuse.comp)
// on lavapipe against the loader's CPU tracer (loader::cone_trace_diffuse), on a baked volume of a
// small lit room with a solid block: same irradiance at random points and normals (CPU without SDF
// steps, as the include), within 1e-3 relative (measured: worst 7.5e-7; float rounding of
// tan/log2/pow could flip a branch at a step boundary on rare points, so up to 1% may differ by
// more, none by more than 5%).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bake/vulkan/vxgi.h"
#include "tests/bake/scene_builders.h"
#include "tests/vulkan/vulkan_test_util.h"
#include "tests/vxgi/vxgi_test_util.h"

namespace gibake {
namespace {

TEST(GpuVxgi, DiffuseConesMatchTheCpuTracer) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  Scene scene;
  const int wall = test::add_material(scene, 0.6f);
  const int light = test::add_material(scene, 0.f, 8.f);
  test::add_box(scene, {-1, 0, -1}, {1, 2, 1}, true, wall);
  test::add_box(scene, {-0.4f, 0, -0.3f}, {0.2f, 0.8f, 0.3f}, false, wall);
  test::add_quad(scene, {-0.3f, 1.99f, -0.3f}, {0.3f, 1.99f, -0.3f}, {0.3f, 1.99f, 0.3f}, {-0.3f, 1.99f, 0.3f},
                 {0, -1, 0}, light);
  VxgiSettings s;
  s.resolution = 20;
  s.rays = 4;
  s.bounces = 1;
  s.calibration_points = 16;
  s.calibration_rays = 16;
  test::VxgiBake bake;
  test::bake_vxgi_scene(scene, s, bake);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.95f, 0.95f), g(-1.f, 1.f);
  std::vector<loader::Vec3> points, normals;
  for (int i = 0; i < 300; ++i) {
    points.push_back({u(rng), 1.f + u(rng), u(rng)});
    loader::Vec3 n{g(rng), g(rng), g(rng)};
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    normals.push_back({n[0] / l, n[1] / l, n[2] / l});
  }
  std::vector<loader::Rgb> gpu;
  const Status st = vxgi_diffuse_gpu(*vk, bake.volume(), points, normals, gpu);
  ASSERT_TRUE(st) << st.message();
  size_t loose = 0, lit = 0;
  float worst = 0.f;
  for (size_t i = 0; i < points.size(); ++i) {
    loader::ConeOptions o;
    o.use_sdf = false;  // the GLSL include takes no SDF steps
    const loader::Rgb cpu = loader::cone_trace_diffuse(bake.volume(), points[i], normals[i], o);
    lit += cpu[0] > 0.f;
    for (int c = 0; c < 3; ++c) {
      const float rel = std::fabs(gpu[i][size_t(c)] - cpu[size_t(c)]) / std::max(1e-3f, cpu[size_t(c)]);
      worst = std::max(worst, rel);
      if (rel > 1e-3f) ++loose;
      EXPECT_LE(rel, 0.05f) << "point " << i << " channel " << c << ": gpu " << gpu[i][size_t(c)] << " cpu " << cpu[size_t(c)];
    }
  }
  std::printf("vxgi diffuse on %s: %zu of %zu values beyond 1e-3 relative, worst %.2e\n", vk->device().name.c_str(),
              loose, points.size() * 3, double(worst));
  EXPECT_GT(lit, points.size() / 2);
  EXPECT_LE(loose, points.size() * 3 / 100);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

}  // namespace
}  // namespace gibake
