// Probe-ray integration on lavapipe (integrate.comp) against the CPU's integrate_radiance and
// integrate_depth. Both sum every output over the probe's rays in ray order, so they differ only by
// rounding (dot products, the shader compiler): required, per probe, SH and irradiance texels within
// 1e-5 x the probe's largest |value| (relative), depth means within 1e-4 m and mean^2 within
// 1e-4 m x 2 x max distance (absolute). The same input twice gives the same bytes.
#include "bake/vulkan/integrate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "io/results/ddgi_result.h"
#include "kernels/integrate.h"
#include "kernels/ray_gen.h"
#include "bake/vulkan/path_pipeline.h"
#include "kernels/sh.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

using kernels::RaySample;
constexpr float kMaxDistance = 12.f;

struct RaySet {
  std::vector<RaySample> samples;
  std::vector<uint32_t> counts;
};

// Random rays: uniform directions, hits at random depths, misses at the max distance, back faces
// pulled in by 0.9 (as the ProbeIntegrator records them), a quarter of the rays dark.
RaySet random_set(uint32_t seed, std::vector<uint32_t> counts = {256, 1, 300, 64, 513, 256, 0, 37}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  RaySet s;
  s.counts = std::move(counts);  // by default: tiles cut, a single ray, none
  for (uint32_t c : s.counts)
    for (uint32_t r = 0; r < c; ++r) {
      kernels::float3 d{g(rng), g(rng), g(rng)};
      d = kernels::normalize(d);
      const float kind = u(rng);
      float depth = kind < 0.2f ? kMaxDistance : 0.05f + 10.f * u(rng);
      if (kind > 0.9f) depth *= 0.9f;
      const bool dark = u(rng) < 0.25f;
      s.samples.push_back({{d.x, d.y, d.z, depth},
                           {dark ? 0.f : 5.f * u(rng), dark ? 0.f : 5.f * u(rng), dark ? 0.f : 50.f * u(rng), 0.f}});
    }
  return s;
}

// The bake's own rays (rotated spherical Fibonacci, 256 per probe) from probes inside an open-top
// room 6 x 3 x 4 m: depth to the nearest wall, misses through the top at the max distance, back
// faces (rays leaving through a thin slab inside) x 0.9, walls lit by a sky-like gradient.
RaySet room_set() {
  RaySet s;
  const uint32_t n = 256;
  std::vector<float> fib(n * 3), dirs(n * 3);
  kernels::spherical_fibonacci_set(n, fib.data());
  const float lo[3] = {0.f, 0.f, 0.f}, hi[3] = {6.f, 3.f, 4.f};
  for (uint32_t p = 0; p < 12; ++p) {
    const float o[3] = {0.3f + 0.45f * p, 0.2f + 0.2f * (p % 7), 0.5f + 0.25f * (p % 11)};
    kernels::generate_probe_rays_from_set(fib.data(), 7, p, 0, n, dirs.data());
    for (uint32_t r = 0; r < n; ++r) {
      const float* d = &dirs[r * 3];
      float t = 1e30f;
      int axis = 0;
      for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.f) continue;
        const float ta = ((d[a] > 0.f ? hi[a] : lo[a]) - o[a]) / d[a];
        if (ta < t) {
          t = ta;
          axis = a;
        }
      }
      const bool miss = axis == 1 && d[1] > 0.f;  // no ceiling
      const bool back = !miss && axis == 0 && d[0] > 0.f && o[0] > 5.f;
      float depth = miss ? kMaxDistance : (back ? t * 0.9f : t);
      depth = std::min(depth, kMaxDistance);
      const float sky = miss ? 1.f + d[1] : 0.f, wall = miss || back ? 0.f : 0.3f + 0.1f * axis;
      s.samples.push_back({{d[0], d[1], d[2], depth}, {sky + wall, sky + 0.8f * wall, 2.f * sky + 0.5f * wall, 0.f}});
    }
    s.counts.push_back(n);
  }
  return s;
}

struct Errors {
  float radiance = 0.f, depth_mean = 0.f, depth_sq = 0.f;  // relative, metres, m^2
};

// GPU against CPU, probe by probe; returns the largest errors seen.
Errors compare(const RaySet& s, const GpuIntegrateResult& g, int sh_order) {
  const int coefs = kernels::sh_coefficient_count(sh_order) * 3, irr = 64 * 3, dep = 256 * 2;
  const std::vector<float> texel_dirs = kernels::oct_tile_directions(kIrradianceTexels);
  const kernels::DepthConeTable cone = kernels::build_depth_cone_table(kDepthTexels);
  Errors e;
  size_t first = 0;
  for (size_t p = 0; p < s.counts.size(); ++p) {
    const int n = int(s.counts[p]);
    std::vector<float> sh(coefs), ir(irr), dp(dep);
    kernels::integrate_radiance(texel_dirs.data(), kIrradianceTexels, &s.samples[first], n, sh_order, sh.data(),
                                ir.data());
    kernels::integrate_depth(cone, &s.samples[first], n, dp.data());
    float peak = 0.f;
    for (float v : sh) peak = std::max(peak, std::fabs(v));
    for (float v : ir) peak = std::max(peak, std::fabs(v));
    if (n > 0) {  // the comparison must see light and depth
      EXPECT_GT(peak, 0.f) << "probe " << p;
      EXPECT_GT(*std::max_element(dp.begin(), dp.end()), 0.f) << "probe " << p;
    }
    for (int i = 0; i < coefs; ++i) {
      const float d = std::fabs(g.sh[p * coefs + i] - sh[i]);
      EXPECT_LE(d, 1e-5f * peak) << "probe " << p << " SH " << i << ": " << g.sh[p * coefs + i] << " vs " << sh[i];
      if (peak > 0.f) e.radiance = std::max(e.radiance, d / peak);
    }
    for (int i = 0; i < irr; ++i) {
      const float d = std::fabs(g.irradiance[p * irr + i] - ir[i]);
      EXPECT_LE(d, 1e-5f * peak) << "probe " << p << " texel value " << i;
      if (peak > 0.f) e.radiance = std::max(e.radiance, d / peak);
    }
    for (int i = 0; i < dep; ++i) {
      const float d = std::fabs(g.depth[p * dep + i] - dp[i]);
      if (i % 2 == 0) {
        EXPECT_LE(d, 1e-4f) << "probe " << p << " depth texel " << i / 2 << " mean";
        e.depth_mean = std::max(e.depth_mean, d);
      } else {
        EXPECT_LE(d, 1e-4f * 2.f * kMaxDistance) << "probe " << p << " depth texel " << i / 2 << " mean^2";
        e.depth_sq = std::max(e.depth_sq, d);
      }
    }
    first += size_t(n);
  }
  return e;
}

void run(const RaySet& s, int sh_order, uint64_t batch_samples, uint32_t batch_probes) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  std::unique_ptr<GpuIntegrator> gi;
  Status st = GpuIntegrator::create(*vk, sh_order, gi, batch_samples, batch_probes);
  ASSERT_TRUE(st) << st.message();
  GpuIntegrateResult a, b;
  st = gi->integrate(s.samples.data(), s.counts, a);
  ASSERT_TRUE(st) << st.message();
  const Errors e = compare(s, a, sh_order);
  std::printf("largest differences: SH and irradiance %.3g of the probe's peak, depth mean %.3g m, mean^2 %.3g m^2\n",
              e.radiance, e.depth_mean, e.depth_sq);
  st = gi->integrate(s.samples.data(), s.counts, b);
  ASSERT_TRUE(st) << st.message();
  EXPECT_EQ(std::memcmp(a.sh.data(), b.sh.data(), a.sh.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.irradiance.data(), b.irradiance.data(), a.irradiance.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * 4), 0);
  EXPECT_GT(gi->kernel_bytes(), 0u);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

TEST(GpuIntegrate, RandomRaysMatchCpu) { run(random_set(1), 2, uint64_t(1) << 20, 8192); }
// Small batches: probes split over several dispatches, a probe larger than the sample batch.
TEST(GpuIntegrate, RandomRaysInSmallBatches) { run(random_set(2), 2, 300, 3); }
// Probes of more rays than one window (GPU_RAY_WINDOW): past lavapipe's 65535 loop iterations an
// invocation, at a window's edge and just past it; the sums continue from window to window.
TEST(GpuIntegrate, ProbesPastTheLoopLimit) { run(random_set(3, {70000, 16384, 16385, 3}), 2, uint64_t(1) << 20, 8192); }
TEST(GpuIntegrate, LowerShOrders) {
  run(random_set(3), 0, uint64_t(1) << 20, 8192);
  run(random_set(4), 1, uint64_t(1) << 20, 8192);
}
TEST(GpuIntegrate, RoomRaysMatchCpu) { run(room_set(), 2, uint64_t(1) << 20, 8192); }

// The resident route as the path pipeline runs it (record_resident in a vk::Recording): the
// samples put where path.comp writes them, batch_probes() probes a submission.
Status integrate_recorded(vk::Context& vk, GpuIntegrator& gi, const std::vector<RaySample>& samples,
                          const std::vector<uint32_t>& counts, bool paired, GpuIntegrateResult& out) {
  out = GpuIntegrateResult{};
  const size_t per_ray = paired ? 2 : 1;
  size_t at = 0;
  for (size_t first = 0; first < counts.size(); first += gi.batch_probes()) {
    const std::vector<uint32_t> part(counts.begin() + first,
                                     counts.begin() + std::min(counts.size(), first + gi.batch_probes()));
    size_t n = 0;
    for (uint32_t c : part) n += c * per_ray;
    vk::Buffer* buffer = nullptr;
    GIBAKE_TRY(gi.reserve_samples(n, buffer));
    if (n) GIBAKE_TRY(vk.upload(*buffer, &samples[at], n * sizeof(RaySample)));
    vk::Recording rec;
    IntegrateRecorded r;
    GIBAKE_TRY(gi.record_resident(part, rec, r, paired));
    GIBAKE_TRY(vk.submit(rec));
    GIBAKE_TRY(vk.wait(rec));
    GpuIntegrateResult got;
    gi.collect(rec, r, got);
    out.sh.insert(out.sh.end(), got.sh.begin(), got.sh.end());
    out.irradiance.insert(out.irradiance.end(), got.irradiance.begin(), got.irradiance.end());
    out.depth.insert(out.depth.end(), got.depth.begin(), got.depth.end());
    at += n;
  }
  return Status::ok();
}

// The resident route (samples written into the integrator's buffer on the device, as path.comp
// does) gives the bytes of the uploading route, in small probe batches too.
TEST(GpuIntegrate, ResidentSamplesMatchUploaded) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const RaySet s = random_set(5);
  std::unique_ptr<GpuIntegrator> gi;
  Status st = GpuIntegrator::create(*vk, 2, gi, 300, 3);
  ASSERT_TRUE(st) << st.message();
  GpuIntegrateResult a, b;
  ASSERT_TRUE(st = gi->integrate(s.samples.data(), s.counts, a)) << st.message();
  ASSERT_TRUE(st = integrate_recorded(*vk, *gi, s.samples, s.counts, false, b)) << st.message();
  EXPECT_EQ(std::memcmp(a.sh.data(), b.sh.data(), a.sh.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.irradiance.data(), b.irradiance.data(), a.irradiance.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * 4), 0);
  vk::Recording rec;
  IntegrateRecorded r;
  EXPECT_FALSE(gi->record_resident({1u << 22}, rec, r));  // more samples than reserved
  EXPECT_FALSE(gi->record_resident(std::vector<uint32_t>(4, 1u), rec, r));  // more probes than a batch
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// Probes whose rays are each followed by a paired emitter sample (bake/trace/path_gather.h): the
// kernel integrates rays and samples together under the rays' norm 4pi/n, and the depth moments
// from the rays only (the samples carry a depth of 777 m that would show), as the CPU does with
// integrate_radiance(..., 2n, norm_count n) and integrate_depth over the n rays; uploaded and
// resident routes alike, in small batches.
TEST(GpuIntegrate, PairedEmitterSamplesMatchCpu) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const RaySet rays = random_set(6), lights = random_set(7);
  std::vector<RaySample> paired;
  size_t first = 0;
  for (uint32_t c : rays.counts) {
    paired.insert(paired.end(), rays.samples.begin() + first, rays.samples.begin() + first + c);
    for (uint32_t r = 0; r < c; ++r) {
      RaySample l = lights.samples[first + r];
      l.dir_depth[3] = 777.f;
      paired.push_back(l);
    }
    first += c;
  }
  std::unique_ptr<GpuIntegrator> gi;
  Status st = GpuIntegrator::create(*vk, 2, gi, 300, 3);
  ASSERT_TRUE(st) << st.message();
  GpuIntegrateResult a, b;
  ASSERT_TRUE(st = gi->integrate(paired.data(), rays.counts, a, true)) << st.message();
  ASSERT_TRUE(st = integrate_recorded(*vk, *gi, paired, rays.counts, true, b)) << st.message();
  EXPECT_EQ(std::memcmp(a.sh.data(), b.sh.data(), a.sh.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.irradiance.data(), b.irradiance.data(), a.irradiance.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * 4), 0);
  const std::vector<float> texel_dirs = kernels::oct_tile_directions(kIrradianceTexels);
  const kernels::DepthConeTable cone = kernels::build_depth_cone_table(kDepthTexels);
  size_t at = 0;
  for (size_t p = 0; p < rays.counts.size(); ++p) {
    const int n = int(rays.counts[p]);
    std::vector<float> sh(27), ir(64 * 3), dp(256 * 2);
    kernels::integrate_radiance(texel_dirs.data(), kIrradianceTexels, &paired[at], 2 * n, 2, sh.data(), ir.data(), n);
    kernels::integrate_depth(cone, &paired[at], n, dp.data());
    float peak = 0.f;
    for (float v : sh) peak = std::max(peak, std::fabs(v));
    for (float v : ir) peak = std::max(peak, std::fabs(v));
    for (int i = 0; i < 27; ++i) EXPECT_LE(std::fabs(a.sh[p * 27 + i] - sh[i]), 1e-5f * peak) << "probe " << p;
    for (int i = 0; i < 64 * 3; ++i)
      EXPECT_LE(std::fabs(a.irradiance[p * 192 + i] - ir[i]), 1e-5f * peak) << "probe " << p;
    for (int i = 0; i < 256 * 2; i += 2) EXPECT_LE(std::fabs(a.depth[p * 512 + i] - dp[i]), 1e-4f) << "probe " << p;
    at += 2 * size_t(n);
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// --target-error's passes on the device (record_accumulate, read_slots): probes in slots out of
// order, stopping after different passes, each pass's rays (then, paired, their emitter samples)
// where path.comp writes them. Without emitter samples every output sums the same floats in the
// same order as one integration of all the probe's rays: the bytes of the uploading route. With
// them the SH and texels sum each pass's rays then its samples (the CPU: all rays, then all
// samples), so they agree with the CPU within integrate's tolerance; the depth moments (rays only)
// keep their bytes.
void accumulate_passes(bool paired) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  constexpr uint32_t kRays = 100;
  const std::vector<uint32_t> slots = {7, 2, 11, 0, 5}, passes = {1, 3, 2, 3, 3};
  std::vector<uint32_t> totals;
  for (uint32_t k : passes) totals.push_back(k * kRays);
  const RaySet rays = random_set(8, totals), lights = random_set(9, totals);
  std::vector<size_t> start;  // each probe's first ray in `rays`
  for (size_t i = 0, at = 0; i < totals.size(); at += totals[i++]) start.push_back(at);
  std::unique_ptr<GpuIntegrator> gi;
  Status st = GpuIntegrator::create(*vk, 2, gi, uint64_t(1) << 20, 8);
  ASSERT_TRUE(st) << st.message();
  ASSERT_TRUE(st = gi->reserve_accumulators(12)) << st.message();
  for (uint32_t k = 0; k < 3; ++k) {
    std::vector<RaySample> pass;
    std::vector<GpuIntegrator::AccumulateProbe> probes;
    for (size_t i = 0; i < slots.size(); ++i) {
      if (passes[i] <= k) continue;
      const size_t at = start[i] + size_t(k) * kRays;
      pass.insert(pass.end(), rays.samples.begin() + at, rays.samples.begin() + at + kRays);
      if (paired) pass.insert(pass.end(), lights.samples.begin() + at, lights.samples.begin() + at + kRays);
      probes.push_back({slots[i], (k + 1) * kRays});
    }
    vk::Buffer* buffer = nullptr;
    ASSERT_TRUE(st = gi->reserve_samples(pass.size(), buffer)) << st.message();
    ASSERT_TRUE(st = vk->upload(*buffer, pass.data(), pass.size() * sizeof(RaySample))) << st.message();
    vk::Recording rec;
    IntegrateRecorded r;
    ASSERT_TRUE(st = gi->record_accumulate(probes, kRays, rec, r, paired)) << st.message();
    ASSERT_TRUE(st = vk->submit(rec)) << st.message();
    ASSERT_TRUE(st = vk->wait(rec)) << st.message();
    GpuIntegrateResult none;
    gi->collect(rec, r, none);
    EXPECT_TRUE(none.sh.empty());  // nothing comes back between passes
  }
  GpuIntegrateResult got;
  ASSERT_TRUE(st = gi->read_slots(0, 12, got)) << st.message();
  const std::vector<float> texel_dirs = kernels::oct_tile_directions(kIrradianceTexels);
  for (size_t i = 0; i < slots.size(); ++i) {
    const uint32_t n = totals[i];
    std::vector<RaySample> all(rays.samples.begin() + start[i], rays.samples.begin() + start[i] + n);
    if (paired) all.insert(all.end(), lights.samples.begin() + start[i], lights.samples.begin() + start[i] + n);
    GpuIntegrateResult one;
    ASSERT_TRUE(st = gi->integrate(all.data(), {n}, one, paired)) << st.message();
    const size_t s = slots[i];
    EXPECT_EQ(std::memcmp(&got.depth[s * 512], one.depth.data(), 512 * 4), 0) << "probe " << i;
    if (!paired) {
      EXPECT_EQ(std::memcmp(&got.sh[s * 27], one.sh.data(), 27 * 4), 0) << "probe " << i;
      EXPECT_EQ(std::memcmp(&got.irradiance[s * 192], one.irradiance.data(), 192 * 4), 0) << "probe " << i;
      continue;
    }
    std::vector<float> sh(27), ir(64 * 3);
    kernels::integrate_radiance(texel_dirs.data(), kIrradianceTexels, all.data(), int(2 * n), 2, sh.data(), ir.data(),
                                int(n));
    float peak = 0.f;
    for (float v : sh) peak = std::max(peak, std::fabs(v));
    for (float v : ir) peak = std::max(peak, std::fabs(v));
    ASSERT_GT(peak, 0.f);
    for (int c = 0; c < 27; ++c) EXPECT_LE(std::fabs(got.sh[s * 27 + c] - sh[c]), 1e-5f * peak) << "probe " << i;
    for (int c = 0; c < 192; ++c)
      EXPECT_LE(std::fabs(got.irradiance[s * 192 + c] - ir[c]), 1e-5f * peak) << "probe " << i;
  }
  EXPECT_FALSE(gi->read_slots(8, 5, got));  // past the slots
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

TEST(GpuIntegrate, AccumulatedPassesMatchOneIntegration) { accumulate_passes(false); }
TEST(GpuIntegrate, AccumulatedPassesWithEmitterSamplesMatchCpu) { accumulate_passes(true); }

}  // namespace
}  // namespace gibake
