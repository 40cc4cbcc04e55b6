// The relocation pass on the Vulkan backend (lavapipe) against the CPU's: same probes moved by
// the same offsets (to 1e-5 m: hit distances agree to float rounding), same states, and the
// records the GPU path writes equal trace_probe_rays' geometry records ray for ray.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/scene/prepare.h"
#include "bake/vulkan/geometry.h"
#include "kernels/ray_gen.h"
#include "tests/bake/scene_builders.h"
#include "tests/vulkan/gpu_test_scenes.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

TEST(GpuRelocate, SameOffsetsAsTheCpu) {
  std::string why;
  if (test::vulkan_missing(why)) GTEST_SKIP() << "no Vulkan device for this test: " << why;
  const Scene scene = test::floor_and_wall();
  DdgiSettings s = test::floor_and_wall_grid(64);
  DdgiResult cpu, gpu;
  DdgiReport rc, rg;
  Context ctx;
  ASSERT_TRUE(bake_ddgi(scene, s, ctx, cpu, rc));
  s.backend.backend = Backend::Vulkan;
  s.backend.vulkan_device = "lavapipe";
  s.backend.validation = true;
  const Status st = bake_ddgi(scene, s, ctx, gpu, rg);
  ASSERT_TRUE(st) << st.message();
  EXPECT_GE(rc.relocated, 9);  // the bottom layer at least; the probes by the wall too
  EXPECT_EQ(rg.relocated, rc.relocated);
  EXPECT_EQ(rg.relocation_rays, rc.relocation_rays);
  ASSERT_EQ(gpu.offsets.size(), cpu.offsets.size());
  for (size_t i = 0; i < cpu.offsets.size(); ++i) EXPECT_NEAR(gpu.offsets[i], cpu.offsets[i], 1e-5f) << i;
  EXPECT_EQ(gpu.states, cpu.states);
  EXPECT_NE(gpu.settings_json.find("\"backend\":\"vulkan\""), std::string::npos);
  EXPECT_EQ(cpu.settings_json.find("\"backend\""), std::string::npos);
}

// geometry_record against trace_probe_rays(shade = false) on the same rays, record by record.
TEST(GpuRelocate, RecordsMatchTheCpuTracer) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const Scene scene = test::floor_and_wall();
  test::Tracers tr;
  ASSERT_TRUE(test::make_tracers(*vk, scene, tr));
  const uint32_t n = 256;
  std::vector<float> fib(n * 3), dirs(n * 3);
  kernels::spherical_fibonacci_set(n, fib.data());
  const std::vector<int32_t> probes = {0, 1, 2};
  const kernels::float3 origins[3] = {{0, 0.01f, 0}, {1.05f, 1, 0}, {0, -1, 0}};  // the last below the floor
  TraceSetup geo;
  geo.prepared = tr.cpu.get();
  geo.shade = false;
  GeometryRays g;
  g.rays_per_probe = n;
  g.origin = [&](int32_t p) { return origins[p]; };
  g.directions = [&](int32_t p, float* d) { kernels::generate_probe_rays_from_set(fib.data(), 5, uint32_t(p), 0, n, d); };
  size_t checked = 0, back = 0;
  g.done = [&](int32_t p, const kernels::HitRecord* rec, const TraceCounters& tc) {
    kernels::generate_probe_rays_from_set(fib.data(), 5, uint32_t(p), 0, n, dirs.data());
    std::vector<kernels::HitRecord> ref(n);
    TraceCounters rc;
    trace_probe_rays(geo, origins[p], uint32_t(p), 0, dirs.data(), n, ref.data(), rc);
    EXPECT_EQ(tc.back_faces, rc.back_faces);
    EXPECT_EQ(tc.rays, rc.rays);
    EXPECT_NEAR(tc.nearest_front, rc.nearest_front, 1e-5f);
    for (uint32_t r = 0; r < n; ++r) {
      EXPECT_EQ(rec[r].kind(), ref[r].kind()) << p << " " << r;
      EXPECT_NEAR(rec[r].dir_t[3], ref[r].dir_t[3], 1e-5f * (1.f + std::fabs(ref[r].dir_t[3])));
      for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(rec[r].dir_t[a], ref[r].dir_t[a]);
        EXPECT_NEAR(rec[r].normal_kind[a], ref[r].normal_kind[a], 1e-6f);
      }
      back += ref[r].kind() == kernels::kHitBack;
      ++checked;
    }
  };
  ASSERT_TRUE(trace_geometry_gpu(*tr.gpu, scene, probes, g, 300));  // several chunks
  EXPECT_EQ(checked, 3u * n);
  EXPECT_GT(back, 0u);  // the single-sided floor seen from below
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

}  // namespace
}  // namespace gibake
