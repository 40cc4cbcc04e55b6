// The GLSL cone tracer engines include (kernels/shaders/vxgi_cone.glsl, run by vxgi_diffuse.comp)
// on lavapipe against the loader's CPU tracer (loader::cone_trace_diffuse), on a baked volume of a
// small lit room with a solid block: same irradiance at random points and normals, with and without
// SDF steps, within 1e-3 relative; float rounding of tan/log2/pow (and, with SDF steps, of the
// trilinear distance that sets the step) can move a sample across a step boundary on rare points,
// so up to 1% may differ by more, none by more than 5%.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bake/vulkan/vxgi.h"
#include "tests/bake/scene_builders.h"
#include "tests/vulkan/vulkan_test_util.h"
#include "tests/vxgi/vxgi_test_util.h"

namespace gibake {
namespace {

// A small lit room with a solid block; `scale` 3 makes it 6 m wide at 36 voxels, where the
// SDF steps change the answer (at 2 m and 20 voxels the free distance never exceeds a step).
void bake_room(test::VxgiBake& bake, float scale = 1.f, int clipmaps = 1, bool cones = false) {
  Scene scene;
  const int wall = test::add_material(scene, 0.6f);
  const int light = test::add_material(scene, 0.f, 8.f);
  auto v = [scale](float x, float y, float z) { return std::array<float, 3>{x * scale, y * scale, z * scale}; };
  test::add_box(scene, v(-1, 0, -1), v(1, 2, 1), true, wall);
  test::add_box(scene, v(-0.4f, 0, -0.3f), v(0.2f, 0.8f, 0.3f), false, wall);
  test::add_quad(scene, v(-0.3f, 1.99f, -0.3f), v(0.3f, 1.99f, -0.3f), v(0.3f, 1.99f, 0.3f), v(-0.3f, 1.99f, 0.3f),
                 {0, -1, 0}, light);
  VxgiSettings s;
  s.resolution = scale > 1.f ? 36 : 20;
  s.clipmaps = clipmaps;
  s.precompute_cones = cones;
  s.rays = 4;
  s.bounces = 1;
  s.calibration_points = 16;
  s.calibration_rays = 16;
  test::bake_vxgi_scene(scene, s, bake);
}

void random_queries(std::vector<loader::Vec3>& points, std::vector<loader::Vec3>& normals, float scale = 1.f) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.95f, 0.95f), g(-1.f, 1.f);
  for (int i = 0; i < 300; ++i) {
    points.push_back({scale * u(rng), scale * (1.f + u(rng)), scale * u(rng)});
    loader::Vec3 n{g(rng), g(rng), g(rng)};
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    normals.push_back({n[0] / l, n[1] / l, n[2] / l});
  }
}

// The kernel against loader::cone_trace_diffuse with the same use_sdf; returns how many points'
// CPU answers the SDF steps changed (when use_sdf).
size_t compare(vk::Context& vk, const loader::VxgiClipmaps& volume, bool use_sdf, float scale = 1.f,
               bool precomputed_cones = false) {
  std::vector<loader::Vec3> points, normals;
  random_queries(points, normals, scale);
  std::vector<loader::Rgb> gpu;
  const Status st = vxgi_diffuse_gpu(vk, volume, points, normals, gpu, use_sdf, precomputed_cones);
  EXPECT_TRUE(st) << st.message();
  if (!st) return 0;
  size_t loose = 0, lit = 0, changed = 0;
  float worst = 0.f;
  for (size_t i = 0; i < points.size(); ++i) {
    loader::ConeOptions o;
    o.use_sdf = use_sdf;
    o.precomputed_cones = precomputed_cones;
    const loader::Rgb cpu = loader::cone_trace_diffuse(volume, points[i], normals[i], o);
    loader::ConeOptions plain;
    plain.use_sdf = false;
    plain.precomputed_cones = precomputed_cones;
    changed += use_sdf && loader::cone_trace_diffuse(volume, points[i], normals[i], plain) != cpu;
    lit += cpu[0] > 0.f;
    for (int c = 0; c < 3; ++c) {
      const float rel = std::fabs(gpu[i][size_t(c)] - cpu[size_t(c)]) / std::max(1e-3f, cpu[size_t(c)]);
      worst = std::max(worst, rel);
      if (rel > 1e-3f) ++loose;
      EXPECT_LE(rel, 0.05f) << "point " << i << " channel " << c << ": gpu " << gpu[i][size_t(c)] << " cpu " << cpu[size_t(c)];
    }
  }
  std::printf("vxgi diffuse on %s (%zu clipmaps, SDF steps %s, changing %zu answers): %zu of %zu values beyond 1e-3 "
              "relative, worst %.2e\n", vk.device().name.c_str(), volume.count, use_sdf ? "on" : "off", changed, loose,
              points.size() * 3, double(worst));
  EXPECT_GT(lit, points.size() / 2);
  EXPECT_LE(loose, points.size() * 3 / 100);
  return changed;
}

TEST(GpuVxgi, DiffuseConesMatchTheCpuTracer) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  test::VxgiBake bake;
  bake_room(bake);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  ASSERT_TRUE(bake.volume().has_sdf());
  compare(*vk, bake.volume(), false);
  compare(*vk, bake.volume(), true);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// The SDF steps matter in the 6 m room (else the comparison with them on would test nothing new):
// the CPU's answers change on many points, and the kernel still matches it.
TEST(GpuVxgi, SdfStepsMatchTheCpuWhereTheyMatter) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  test::VxgiBake bake;
  bake_room(bake, 3.f);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_GT(compare(*vk, bake.volume(), true, 3.f), 30u);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// Three clipmaps (io/loader/src/vxgi_cone.cpp picks the finest holding each footprint, blends at
// borders): the kernel over every clipmap against the CPU. This once differed on 17 of 300 points
// on lavapipe: llvmpipe ends every loop after 65535 loop iterations in an invocation, and the
// include's nested level-size loops used them up within the sixth cone (vxgi_cone.glsl).
TEST(GpuVxgi, ClipmapsMatchTheCpuTracer) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  test::VxgiBake bake;
  bake_room(bake, 3.f, 3);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  ASSERT_EQ(bake.file.vxgi_volumes().size(), 3u);
  compare(*vk, bake.file.vxgi_volumes(), false, 3.f);
  compare(*vk, bake.file.vxgi_volumes(), true, 3.f);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// The 16 precomputed cone directions reading the precomputed slices (--vxgi-precompute-cones) over two clipmaps:
// the include's gibake_vxgi_cone_trace_diffuse_precomputed against the loader with ConeOptions::precomputed_cones.
// The slices must change the answer (else this would only test the faces again): the same query
// on the faces alone (a volume without slices) differs on most points.
TEST(GpuVxgi, PrecomputedConeSlicesMatchTheCpuTracer) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  test::VxgiBake with, without;
  bake_room(with, 1.f, 2, true);
  bake_room(without, 1.f, 2, false);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  ASSERT_EQ(with.file.vxgi_volumes()[0].faces(), 22u);
  compare(*vk, with.file.vxgi_volumes(), true, 1.f, true);
  std::vector<loader::Vec3> points, normals;
  random_queries(points, normals);
  loader::ConeOptions o;
  o.precomputed_cones = true;
  size_t differ = 0;
  for (size_t i = 0; i < points.size(); ++i)
    differ += loader::cone_trace_diffuse(with.file.vxgi_volumes(), points[i], normals[i], o) !=
              loader::cone_trace_diffuse(without.file.vxgi_volumes(), points[i], normals[i], o);
  EXPECT_GT(differ, points.size() / 2);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// The include's gibake_vxgi_cone_trace_specular against loader::cone_trace_specular over three
// clipmaps with SDF steps: random points, normals, eyes and roughness 0..1 (cones of 0.05 to pi/2),
// radiance and alpha within 1e-3 relative (up to 1% of values beyond it, none beyond 5%, as for
// the diffuse set); most cones must see something (else the comparison would test nothing).
TEST(GpuVxgi, SpecularConeMatchesTheCpuTracer) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  test::VxgiBake bake;
  bake_room(bake, 3.f, 3);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  const loader::VxgiClipmaps& volume = bake.file.vxgi_volumes();
  std::vector<loader::Vec3> points, normals;
  random_queries(points, normals, 3.f);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> g(-1.f, 1.f), u(0.f, 1.f);
  std::vector<SpecularQuery> queries;
  for (size_t i = 0; i < points.size(); ++i) {
    loader::Vec3 e{g(rng), g(rng), g(rng)};
    const float d = e[0] * normals[i][0] + e[1] * normals[i][1] + e[2] * normals[i][2];
    if (d < 0.f)  // the viewer in front of the surface
      for (int c = 0; c < 3; ++c) e[size_t(c)] -= 2.f * d * normals[i][size_t(c)];
    queries.push_back({points[i], normals[i], e, u(rng)});
  }
  std::vector<loader::Rgba> gpu;
  const Status st = vxgi_specular_gpu(*vk, volume, queries, gpu);
  ASSERT_TRUE(st) << st.message();
  size_t loose = 0, seen = 0;
  float worst = 0.f;
  for (size_t i = 0; i < queries.size(); ++i) {
    const SpecularQuery& q = queries[i];
    const loader::ConeResult cpu = loader::cone_trace_specular(volume, q.point, q.normal, q.to_eye, q.roughness);
    const float want[4] = {cpu.radiance[0], cpu.radiance[1], cpu.radiance[2], cpu.alpha};
    seen += cpu.alpha > 0.5f;
    for (int c = 0; c < 4; ++c) {
      const float rel = std::fabs(gpu[i][size_t(c)] - want[c]) / std::max(1e-3f, std::fabs(want[c]));
      worst = std::max(worst, rel);
      loose += rel > 1e-3f;
      EXPECT_LE(rel, 0.05f) << "query " << i << " value " << c << ": gpu " << gpu[i][size_t(c)] << " cpu " << want[c];
    }
  }
  std::printf("vxgi specular on %s: %zu of %zu values beyond 1e-3 relative, worst %.2e; %zu of %zu cones opaque\n",
              vk->device().name.c_str(), loose, queries.size() * 4, double(worst), seen, queries.size());
  EXPECT_GT(seen, queries.size() / 2);
  EXPECT_LE(loose, queries.size() * 4 / 100);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

}  // namespace
}  // namespace gibake
