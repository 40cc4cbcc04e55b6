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
#include "bake/vulkan/relocate.h"
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

// A relocation object that served one volume serves the next (the session hands it on): it says
// so only for the same tracer, scene and direction set, and its sums for other probes, seeds and
// positions equal a fresh object's bit for bit, so the reuse leaves no trace in a bake.
TEST(GpuRelocate, ReusedForALaterVolume) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const Scene scene = test::floor_and_wall();
  const Scene other = test::floor_and_wall();
  test::Tracers tr;
  ASSERT_TRUE(test::make_tracers(*vk, scene, tr));
  const uint32_t n = 64;
  std::vector<float> fib(n * 3), fib_more(2 * n * 3);
  kernels::spherical_fibonacci_set(n, fib.data());
  kernels::spherical_fibonacci_set(2 * n, fib_more.data());
  const uint64_t chunk_rays = 5 * n;  // several chunks
  std::unique_ptr<GpuRelocation> used, fresh;
  ASSERT_TRUE(GpuRelocation::create(*tr.gpu, scene, fib.data(), n, used, chunk_rays));
  if (!used) GTEST_SKIP() << "the device has no shaderFloat64: relocation keeps the per-ray path";
  EXPECT_TRUE(used->serves(*tr.gpu, scene, fib.data(), n));
  EXPECT_FALSE(used->serves(*tr.gpu, other, fib.data(), n));
  EXPECT_FALSE(used->serves(*tr.gpu, scene, fib_more.data(), 2 * n));
  std::vector<float> turned = fib;
  turned[0] = -turned[0];
  EXPECT_FALSE(used->serves(*tr.gpu, scene, turned.data(), n));

  // The first volume: 7 probes near the floor's corner.
  const auto first_at = [](int32_t p) { return kernels::float3{0.1f * float(p), 0.05f, 0.2f}; };
  std::vector<int32_t> first(7);
  for (int32_t p = 0; p < 7; ++p) first[size_t(p)] = p;
  std::vector<RelocationSums> sums;
  ASSERT_TRUE(used->sums(first, 3, 0, first_at, 0.3f, sums));
  // The next: more probes than the first reserved, other positions, seed, pass and threshold.
  const auto next_at = [](int32_t p) { return kernels::float3{1.0f - 0.02f * float(p), 0.04f, 0.1f * float(p % 5)}; };
  std::vector<int32_t> next;
  for (int32_t p = 0; p < 23; ++p) next.push_back(2 * p + 1);
  std::vector<RelocationSums> reused, made;
  ASSERT_TRUE(used->sums(next, 11, 1, next_at, 0.25f, reused));
  ASSERT_TRUE(GpuRelocation::create(*tr.gpu, scene, fib.data(), n, fresh, chunk_rays));
  ASSERT_TRUE(fresh->sums(next, 11, 1, next_at, 0.25f, made));
  ASSERT_EQ(reused.size(), next.size());
  ASSERT_EQ(made.size(), next.size());
  int close = 0;
  for (size_t i = 0; i < next.size(); ++i) {
    EXPECT_EQ(reused[i].close, made[i].close) << i;
    EXPECT_EQ(reused[i].nearest, made[i].nearest) << i;
    for (int a = 0; a < 3; ++a) EXPECT_EQ(reused[i].delta[a], made[i].delta[a]) << i;
    close += made[i].close;
  }
  EXPECT_GT(close, 0);  // the probes sit 4 cm over the floor: the sums are not empty
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

}  // namespace
}  // namespace gibake
