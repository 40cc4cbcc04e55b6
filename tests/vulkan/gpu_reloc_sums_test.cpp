// Relocation statistics on the device (raygen.comp mode 1, traverse.comp, reloc_sums.comp) against
// their CPU twin: relocation_sums over trace_probe_rays(shade = false) records of the same rays.
// Tolerances: the close flag equal; nearest within 1e-5·(1 + t) m (hit distances agree to float
// rounding); delta within 1e-5·threshold·rays per component (a grazing ray whose front/back or
// close decision flips moves delta by at most threshold); Embree's and traverse.comp's hit
// distances differ only at float rounding. And against
// the per-ray route (the same device hits reduced on the host): within 1e-6·threshold·rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/ddgi/relocate_stage.h"
#include "bake/scene/prepare.h"
#include "bake/vulkan/geometry.h"
#include "bake/vulkan/relocate.h"
#include "io/gltf/import.h"
#include "kernels/ray_gen.h"
#include "tests/bake/scene_builders.h"
#include "tests/vulkan/gpu_test_scenes.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

struct Box {
  kernels::float3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
};

Box bounds(const Scene& s) {
  Box b;
  for (size_t i = 0; i + 2 < s.positions.size(); i += 3) {
    b.lo = {std::min(b.lo.x, s.positions[i]), std::min(b.lo.y, s.positions[i + 1]),
            std::min(b.lo.z, s.positions[i + 2])};
    b.hi = {std::max(b.hi.x, s.positions[i]), std::max(b.hi.y, s.positions[i + 1]),
            std::max(b.hi.z, s.positions[i + 2])};
  }
  return b;
}

// A 5x5x5 grid spanning the scene's box inset by 2%, so the outer layers sit near walls.
std::vector<kernels::float3> grid_in(const Box& b) {
  std::vector<kernels::float3> out;
  const kernels::float3 e = b.hi - b.lo;
  for (int z = 0; z < 5; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 5; ++x) {
        const float f[3] = {0.02f + 0.24f * x, 0.02f + 0.24f * y, 0.02f + 0.24f * z};
        out.push_back({b.lo.x + e.x * f[0], b.lo.y + e.y * f[1], b.lo.z + e.z * f[2]});
      }
  return out;
}

struct Tally {
  size_t close = 0;
  double max_delta = 0, max_nearest = 0;
  double route_delta = 0, route_nearest = 0;  // against the per-ray route's sums of the same GPU hits
};

// relocation_sums of the per-ray route (trace_geometry_gpu + geometry_record): the same device
// hits reduced on the host, what the Vulkan backend did before the sums moved to the device.
std::vector<RelocationSums> per_ray_route(GpuTracer& tracer, const Scene& scene, const std::vector<int32_t>& probes,
                                          const std::vector<kernels::float3>& origins, const float* fib, uint32_t n,
                                          uint64_t seed, uint32_t pass, float threshold) {
  std::vector<RelocationSums> out(probes.size());
  GeometryRays g;
  g.rays_per_probe = n;
  g.origin = [&](int32_t p) { return origins[size_t(p)]; };
  g.directions = [&](int32_t p, float* d) {
    kernels::generate_probe_rays_from_set(fib, seed, uint32_t(p), pass, n, d);
  };
  g.done = [&](int32_t p, const kernels::HitRecord* rec, const TraceCounters&) {
    out[size_t(p)] = relocation_sums(rec, n, threshold);
  };
  EXPECT_TRUE(trace_geometry_gpu(tracer, scene, probes, g));
  return out;
}

Tally compare(vk::Context& vk, const Scene& scene, const std::vector<kernels::float3>& origins, float threshold) {
  Tally t;
  test::Tracers tr;
  if (!test::make_tracers(vk, scene, tr)) return t;
  const uint32_t n = 128, pass = kRelocatePassBase + 1;
  const uint64_t seed = 7;
  std::vector<float> fib(n * 3), dirs(n * 3);
  kernels::spherical_fibonacci_set(n, fib.data());
  std::unique_ptr<GpuRelocation> reloc;
  EXPECT_TRUE(GpuRelocation::create(*tr.gpu, scene, fib.data(), n, reloc, 1000));  // several chunks
  if (!reloc) {
    ADD_FAILURE() << "the test device has no shaderFloat64";
    return t;
  }
  std::vector<int32_t> probes(origins.size());
  for (size_t i = 0; i < probes.size(); ++i) probes[i] = int32_t(i);
  std::vector<RelocationSums> gpu;
  EXPECT_TRUE(reloc->sums(
      probes, seed, pass, [&](int32_t p) { return origins[size_t(p)]; }, threshold, gpu));
  // Two chunks in flight over shared device buffers change nothing: one chunk of every probe gives
  // the same sums, bit for bit.
  std::unique_ptr<GpuRelocation> whole;
  EXPECT_TRUE(GpuRelocation::create(*tr.gpu, scene, fib.data(), n, whole));
  std::vector<RelocationSums> one_chunk;
  if (whole) {
    EXPECT_TRUE(whole->sums(
        probes, seed, pass, [&](int32_t p) { return origins[size_t(p)]; }, threshold, one_chunk));
  }
  EXPECT_EQ(one_chunk.size(), gpu.size());
  for (size_t i = 0; i < std::min(one_chunk.size(), gpu.size()); ++i) {
    EXPECT_EQ(one_chunk[i].close, gpu[i].close) << i;
    EXPECT_EQ(one_chunk[i].nearest, gpu[i].nearest) << i;
    for (int a = 0; a < 3; ++a) EXPECT_EQ(one_chunk[i].delta[a], gpu[i].delta[a]) << i << " " << a;
  }
  const std::vector<RelocationSums> route =
      per_ray_route(*tr.gpu, scene, probes, origins, fib.data(), n, seed, pass, threshold);
  TraceSetup geo;
  geo.prepared = tr.cpu.get();
  geo.shade = false;
  std::vector<kernels::HitRecord> rec(n);
  const double delta_tol = 1e-5 * threshold * n;
  for (size_t i = 0; i < probes.size(); ++i) {
    kernels::generate_probe_rays_from_set(fib.data(), seed, uint32_t(i), pass, n, dirs.data());
    TraceCounters tc;
    trace_probe_rays(geo, origins[i], uint32_t(i), pass, dirs.data(), n, rec.data(), tc);
    const RelocationSums cpu = relocation_sums(rec.data(), n, threshold);
    EXPECT_EQ(gpu[i].close, cpu.close) << i;
    t.close += cpu.close;
    const double dn = std::fabs(double(gpu[i].nearest) - cpu.nearest);
    EXPECT_LE(dn, 1e-5 * (1.0 + cpu.nearest)) << i;
    t.max_nearest = std::max(t.max_nearest, dn);
    EXPECT_EQ(gpu[i].close, route[i].close) << i;
    t.route_nearest = std::max(t.route_nearest, std::fabs(double(gpu[i].nearest) - route[i].nearest));
    for (int a = 0; a < 3; ++a) {
      t.route_delta = std::max(t.route_delta, std::fabs(gpu[i].delta[a] - route[i].delta[a]));
      const double dd = std::fabs(gpu[i].delta[a] - cpu.delta[a]);
      EXPECT_LE(dd, delta_tol) << i << " " << a;
      t.max_delta = std::max(t.max_delta, dd);
    }
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS((&vk));
  // The same hits, reduced on the device or on the host: equal up to the device's direction
  // rounding (raygen.comp: within 1e-6 of the CPU's; bit-identical on lavapipe).
  EXPECT_LE(t.route_delta, 1e-6 * threshold * n);
  EXPECT_LE(t.route_nearest, 1e-6 * (1.0 + threshold));
  std::printf(
      "%zu probes, %zu close; largest differences against Embree's records: delta %.3g, nearest %.3g; "
      "against the per-ray route: delta %.3g, nearest %.3g\n",
      probes.size(), t.close, t.max_delta, t.max_nearest, t.route_delta, t.route_nearest);
  return t;
}

TEST(GpuRelocSums, CornellBoxNvproMatchesTheCpuTwin) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  Scene s;
  const Status st =
      import_scene(std::string(GIBAKE_ASSETS_DIR) + "/cornell-box-nvpro/cornellBox.gltf", {}, Context{}, s);
  ASSERT_TRUE(st) << st.message();
  const Box b = bounds(s);
  const kernels::float3 e = b.hi - b.lo;
  const float threshold = 0.1f * std::min({e.x, e.y, e.z});
  const Tally t = compare(*vk, s, grid_in(b), threshold);
  EXPECT_GT(t.close, 20u);  // the outer layers see walls within the threshold
}

// Back faces (a single-sided floor seen from below) and a double-sided wall, whose back is a front.
TEST(GpuRelocSums, SidednessMatchesTheCpuTwin) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const Scene s = test::floor_and_wall();
  const std::vector<kernels::float3> origins = {{0, 0.01f, 0}, {1.05f, 1, 0}, {1.15f, 1, 0}, {0, -0.01f, 0}, {0, 3, 0}};
  const Tally t = compare(*vk, s, origins, 0.2f);
  EXPECT_EQ(t.close, 3u);  // above the floor, either side of the double-sided wall; not below the floor
}

// With ray capture (benchmarks) the stage keeps the per-ray route; both routes move the same
// probes by the same offsets, bit for bit (the same device hits and the same sums).
TEST(GpuRelocSums, CaptureKeepsThePerRayRoute) {
  std::string why;
  if (test::vulkan_missing(why)) GTEST_SKIP() << "no Vulkan device for this test: " << why;
  const Scene scene = test::floor_and_wall();
  DdgiSettings s = test::floor_and_wall_grid(16);
  s.backend.backend = Backend::Vulkan;
  s.backend.vulkan_device = "lavapipe";
  s.backend.validation = true;
  Context ctx;
  DdgiResult sums, per_ray;
  DdgiReport rs, rp;
  Status st = bake_ddgi(scene, s, ctx, sums, rs);
  ASSERT_TRUE(st) << st.message();
  RayCapture captured;
  const PipelineDevices platform;
  RunContext capture_run;
  capture_run.platform = &platform;
  capture_run.capture_rays = &captured;
  st = bake_ddgi(scene, s, capture_run, ctx, per_ray, rp);
  ASSERT_TRUE(st) << st.message();
  size_t relocation_rays = 0;
  for (const auto& list : captured)
    for (const auto& r : list) relocation_rays += r.kind == CapturedRay::kRelocation;
  EXPECT_EQ(relocation_rays, rs.relocation_rays);  // the per-ray route ran and recorded its rays
  EXPECT_GE(rs.relocated, 9);
  EXPECT_EQ(rp.relocated, rs.relocated);
  EXPECT_EQ(per_ray.offsets, sums.offsets);
  EXPECT_EQ(per_ray.states, sums.states);
}

}  // namespace
}  // namespace gibake
