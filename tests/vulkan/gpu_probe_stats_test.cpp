// The per-probe statistics kernel (probe_stats.comp, bake/vulkan/probe_stats.h) against the CPU's
// path from the same briefs: path_record + count_path (counters), RunningStats over ray_stop_value
// (Welford in double, ray order) and ray_test_counts (misses, saw light). Batches that split probes
// check that a probe continues across path batches, and probes of more rays than a window
// (GPU_RAY_WINDOW) that it continues across windows.
#include "bake/vulkan/probe_stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "bake/ddgi/trace_batches.h"
#include "bake/vulkan/path.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

// Random briefs: misses (t -1, sky or black), front and back hits, dark and lit rays, counters.
std::vector<gpu::GpuPathBrief> random_briefs(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<gpu::GpuPathBrief> b(n);
  for (size_t i = 0; i < n; ++i) {
    const uint32_t kind = uint32_t(rng() % 3);
    const bool dark = u(rng) < 0.3f;
    const float t = kind == 0 ? -1.f : 0.01f + 20.f * u(rng);
    b[i].radiance_t = {dark ? 0.f : 50.f * u(rng), dark ? 0.f : u(rng), dark ? 0.f : 1e-3f * u(rng), t};
    b[i].counts = {uint32_t(rng() % 9), uint32_t(rng() % 5), kind == 2 ? 1u : 0u, kind};
  }
  return b;
}

struct CpuStats {
  TraceCounters counters;
  RunningStats luminance;
  ProbeRayTest test;
};

CpuStats cpu_stats(const gpu::GpuPathBrief* b, uint32_t n) {
  CpuStats s;
  std::vector<kernels::HitRecord> h(n);
  for (uint32_t r = 0; r < n; ++r) {
    h[r] = path_record(b[r], s.counters);
    s.luminance.add(ray_stop_value(h[r].radiance0, nullptr));
  }
  s.test = ray_test_counts(h.data(), n);
  return s;
}

// Reduces `probes` probes of `per_probe` random briefs on the device in batches of `batch` rays.
void check(uint32_t probes, uint32_t per_probe, uint32_t batch) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  if (!vk->shader_float64()) GTEST_SKIP() << vk->device().name << " has no shaderFloat64";
  std::unique_ptr<GpuProbeStatsReducer> reducer;
  ASSERT_TRUE(GpuProbeStatsReducer::create(*vk, reducer));
  ASSERT_TRUE(reducer->reserve(probes));
  const uint64_t total = uint64_t(probes) * per_probe;
  const std::vector<gpu::GpuPathBrief> briefs = random_briefs(total, probes * 31 + per_probe);
  vk::Buffer buffer;
  ASSERT_TRUE(vk->create_buffer(uint64_t(batch) * sizeof(gpu::GpuPathBrief), buffer, "briefs"));
  for (uint64_t first = 0; first < total; first += batch) {
    const uint32_t n = uint32_t(std::min<uint64_t>(batch, total - first));
    ASSERT_TRUE(vk->upload(buffer, &briefs[first], uint64_t(n) * sizeof(gpu::GpuPathBrief)));
    ASSERT_TRUE(vk->run(reducer->dispatch(buffer, uint32_t(first), n, per_probe)));
  }
  std::vector<gpu::GpuProbeStats> out;
  ASSERT_TRUE(reducer->download(probes, out));
  double worst = 0.0;
  for (uint32_t p = 0; p < probes; ++p) {
    const CpuStats want = cpu_stats(&briefs[size_t(p) * per_probe], per_probe);
    CpuStats got;
    unpack_probe_stats(out[p], got.counters, got.test, got.luminance);
    // Counts exact; the nearest front t is a minimum of the same floats: exact too.
    EXPECT_EQ(got.counters.rays, want.counters.rays) << p;
    EXPECT_EQ(got.counters.shadow_rays, want.counters.shadow_rays) << p;
    EXPECT_EQ(got.counters.bounce_rays, want.counters.bounce_rays) << p;
    EXPECT_EQ(got.counters.back_faces, want.counters.back_faces) << p;
    EXPECT_EQ(got.counters.nearest_front, want.counters.nearest_front) << p;
    EXPECT_EQ(got.test.rays, want.test.rays) << p;
    EXPECT_EQ(got.test.misses, want.test.misses) << p;
    EXPECT_EQ(got.test.saw_light, want.test.saw_light) << p;
    EXPECT_EQ(got.luminance.n, want.luminance.n) << p;
    // Welford in double in the same order: bit-identical where the device rounds double division
    // correctly (lavapipe); 1e-12 relative allows a few ulps per step on devices that do not.
    const auto rel = [](double a, double b) { return std::fabs(a - b) / std::max(std::fabs(b), 1e-300); };
    EXPECT_LE(rel(got.luminance.mean, want.luminance.mean), 1e-12) << p;
    EXPECT_LE(rel(got.luminance.m2, want.luminance.m2), 1e-12) << p;
    EXPECT_LE(std::fabs(got.luminance.relative_error() - want.luminance.relative_error()),
              1e-12 * want.luminance.relative_error())
        << p;
    worst = std::max({worst, rel(got.luminance.mean, want.luminance.mean), rel(got.luminance.m2, want.luminance.m2)});
  }
  std::printf("probe stats: %u probes x %u rays, batches of %u: worst relative difference of mean/m2 %.3g\n", probes,
              per_probe, batch, worst);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

TEST(GpuProbeStats, WholeProbesPerBatch) { check(40, 256, 1024); }
TEST(GpuProbeStats, ProbesStraddleBatches) { check(37, 100, 320); }
TEST(GpuProbeStats, ManyBatchesPerProbe) { check(5, 1000, 64); }
TEST(GpuProbeStats, OneBatch) { check(300, 7, 4096); }
// Past lavapipe's 65535 loop iterations an invocation: each probe's rays in windows of
// GPU_RAY_WINDOW, whole probes in a batch and probes straddling batches and windows.
TEST(GpuProbeStats, RaysPastTheLoopLimit) { check(2, 65536, 131072); }
TEST(GpuProbeStats, WindowsStraddleBatches) { check(3, 40000, 50000); }

}  // namespace
}  // namespace gibake
