// The probe-feedback bounce passes on lavapipe (bounce_weights.comp, bounce_pass.comp) against the
// CPU: kernels::ddgi_probe_weights and run_bounce_passes on the same inputs -- a room with an
// inner wall, probes with relocation offsets, a sixth of them inactive, depth moments traced
// against the room (mean, mean^2 with a variance), hits on its walls.
// Tolerances: the weights kernel sums the 8 weights in float where the CPU sums in double, so the
// probe lists must be identical and every weight within 2e-6 (a few ulp of a weight <= 1); the
// passes sum every output in the CPU's ray order, so per probe SH and irradiance texels must be
// within 1e-5 x the probe's largest |value| (relative). Streaming the hits in chunks gives the same
// bytes as one chunk, and the same input twice gives the same bytes.
#include "bake/vulkan/bounce.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "io/results/ddgi_result.h"
#include "kernels/integrate.h"
#include "kernels/octahedral.h"
#include "kernels/sh.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

using kernels::float3;
constexpr float kRoom[3] = {6.f, 3.f, 4.f};
constexpr int kTile = kDepthTexels + 2;

// Distance from o along unit d to the room's walls or the inner wall (x = 3, y < 1.6); the
// normal there, facing the ray.
float trace_room(const float3& o, const float3& d, float3& normal) {
  float t = 1e30f;
  const float oa[3] = {o.x, o.y, o.z}, da[3] = {d.x, d.y, d.z};
  int axis = 0;
  for (int a = 0; a < 3; ++a) {
    if (da[a] == 0.f) continue;
    const float ta = ((da[a] > 0.f ? kRoom[a] : 0.f) - oa[a]) / da[a];
    if (ta < t) t = ta, axis = a;
  }
  if (d.x != 0.f) {
    const float tw = (3.f - o.x) / d.x;
    if (tw > 1e-4f && tw < t && o.y + d.y * tw < 1.6f) t = tw, axis = 0;
  }
  float n[3] = {0.f, 0.f, 0.f};
  n[axis] = da[axis] > 0.f ? -1.f : 1.f;
  normal = {n[0], n[1], n[2]};
  return t;
}

struct Inputs {
  std::vector<float> offsets, positions, depth_tiles, sh0, irradiance, texel_dirs;
  std::vector<uint8_t> inactive;
  std::vector<uint32_t> probe_rays;
  std::vector<std::vector<BounceHit>> hits;
  BounceInputs bi;
};

// Depth moments of one probe: per texel the distance to the room along the texel's direction,
// mean^2 with a 5% standard deviation (bordered tile).
void depth_tile(const float3& pos, float* tile) {
  for (int y = 0; y < kDepthTexels; ++y)
    for (int x = 0; x < kDepthTexels; ++x) {
      float3 n;
      const float m = trace_room(pos, kernels::oct_texel_direction(x, y, kDepthTexels), n);
      float* t = tile + ((y + 1) * kTile + x + 1) * 2;
      t[0] = m;
      t[1] = m * m * (1.f + 0.05f * 0.05f);
    }
  kernels::oct_fill_border(tile, kTile, 2, 0, 0, kDepthTexels);
}

// `big` > 0: probe 7 gets that many hits (more than a window of the pass kernel).
Inputs make_inputs(uint32_t seed, int sh_order, int bounces, uint32_t big = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  Inputs in;
  const int counts[3] = {6, 3, 4};
  const int n = counts[0] * counts[1] * counts[2];
  const int values = kernels::sh_coefficient_count(sh_order) * 3;
  in.offsets.resize(n * 3);
  in.positions.resize(n * 3);
  in.depth_tiles.resize(size_t(n) * kTile * kTile * 2);
  in.inactive.resize(n);
  in.probe_rays.resize(n);
  in.hits.resize(n);
  in.sh0.resize(size_t(n) * values);
  in.irradiance.resize(size_t(n) * kIrradianceTexels * kIrradianceTexels * 3);
  for (float& v : in.irradiance) v = 100.f * u(rng);
  for (int p = 0; p < n; ++p) {
    const int c[3] = {p % counts[0], (p / counts[0]) % counts[1], p / (counts[0] * counts[1])};
    for (int a = 0; a < 3; ++a) {
      in.offsets[p * 3 + a] = 0.3f * (u(rng) - 0.5f);
      in.positions[p * 3 + a] = 0.5f + c[a] + in.offsets[p * 3 + a];
    }
    const float3 pos = kernels::load3(&in.positions[p * 3]);
    depth_tile(pos, &in.depth_tiles[size_t(p) * kTile * kTile * 2]);
    in.inactive[p] = u(rng) < 0.16f;
    const float dc = 50.f * u(rng);
    for (int k = 0; k < values; ++k) in.sh0[p * values + k] = k < 3 ? dc * (0.5f + u(rng)) : 0.3f * dc * g(rng);
    // Hit counts that cut the pass kernel's 128-hit tiles, a probe without hits, one with a single hit.
    const uint32_t hits = p == 5 ? 0 : p == 6 ? 1 : p == 7 && big ? big : uint32_t(300 * u(rng));
    in.probe_rays[p] = hits + uint32_t(40 * u(rng));
    for (uint32_t r = 0; r < hits; ++r) {
      const float3 d = kernels::normalize(float3{g(rng), g(rng), g(rng)});
      float3 normal;
      const float t = trace_room(pos, d, normal);
      const float3 a{0.9f * u(rng), 0.9f * u(rng), 0.9f * u(rng)};
      in.hits[p].push_back(BounceHit{{d.x, d.y, d.z, t}, {normal.x, normal.y, normal.z}, {a.x, a.y, a.z}});
    }
  }
  in.texel_dirs = kernels::oct_tile_directions(kIrradianceTexels);
  BounceInputs& bi = in.bi;
  for (int a = 0; a < 3; ++a) {
    bi.volume.grid_min[a] = 0.5f;
    bi.volume.spacing[a] = 1.f;
    bi.volume.counts[a] = counts[a];
  }
  bi.volume.params[0] = 0.02f;
  bi.volume.params[1] = 0.3f;
  bi.volume.offsets = in.offsets.data();
  bi.volume.inactive = in.inactive.data();
  bi.volume.depth_tiles = in.depth_tiles.data();
  bi.volume.depth_res = kDepthTexels;
  bi.positions = in.positions.data();
  bi.sh0 = &in.sh0;
  bi.hits = &in.hits;
  bi.probe_rays = in.probe_rays.data();
  bi.texel_dirs = in.texel_dirs.data();
  bi.sh_order = sh_order;
  bi.bounces = bounces;
  bi.energy_conservation = 0.9f;
  return in;
}

// Largest |a - b| over a probe's values divided by the probe's largest |b|, over all probes.
double max_relative(const std::vector<float>& a, const std::vector<float>& b, size_t per_probe) {
  double worst = 0.0;
  for (size_t p = 0; p * per_probe < b.size(); ++p) {
    double scale = 0.0, diff = 0.0;
    for (size_t k = p * per_probe; k < (p + 1) * per_probe; ++k) {
      scale = std::max(scale, double(std::fabs(b[k])));
      diff = std::max(diff, double(std::fabs(a[k] - b[k])));
    }
    if (scale > 0.0)
      worst = std::max(worst, diff / scale);
    else
      worst = std::max(worst, diff);
  }
  return worst;
}

TEST(GpuBounce, WeightsMatchCpu) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  for (uint32_t seed : {1u, 2u}) {
    Inputs in = make_inputs(seed, 2, 1);
    for (uint64_t chunk : {uint64_t(1) << 21, uint64_t(700)}) {
      GpuBounceOptions opt;
      opt.chunk_hits = chunk;
      std::vector<kernels::ProbeWeights> gpu;
      const Status st = gpu_bounce_weights(*vk, in.bi, gpu, opt);
      ASSERT_TRUE(st) << st.message();
      size_t i = 0, compared = 0;
      double worst = 0.0;
      for (size_t p = 0; p < in.hits.size(); ++p)
        for (const BounceHit& h : in.hits[p]) {
          const float3 hit = kernels::load3(&in.positions[p * 3]) + kernels::load3(h.dir_t) * h.dir_t[3];
          const kernels::ProbeWeights cpu = kernels::ddgi_probe_weights(in.bi.volume, hit, kernels::load3(h.normal));
          const kernels::ProbeWeights& gw = gpu[i++];
          ASSERT_EQ(gw.count, cpu.count) << "hit " << i - 1;
          for (int k = 0; k < cpu.count; ++k) {
            EXPECT_EQ(gw.probe[k], cpu.probe[k]) << "hit " << i - 1;
            worst = std::max(worst, double(std::fabs(gw.weight[k] - cpu.weight[k])));
          }
          compared += cpu.count > 0;
        }
      EXPECT_LE(worst, 2e-6);
      EXPECT_GT(compared, 1000u);
      std::printf("seed %u chunk %llu: %zu hits, largest weight difference %.3g\n", seed,
                  static_cast<unsigned long long>(chunk), i, worst);
    }
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

struct Case {
  int sh_order, bounces;
};

TEST(GpuBounce, PassesMatchCpu) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  tbb::task_arena arena(2);
  const Context ctx;
  for (const Case& c : {Case{2, 3}, Case{1, 1}, Case{2, 0}}) {
    Inputs in = make_inputs(7, c.sh_order, c.bounces);
    std::vector<float> cpu_sh, cpu_irr = in.irradiance;
    BounceTimes times;
    run_bounce_passes(in.bi, arena, ctx, cpu_sh, cpu_irr, times);
    std::vector<float> gpu_sh, gpu_irr = in.irradiance;
    GpuBounceStats stats;
    const Status st = run_bounce_passes_gpu(*vk, in.bi, gpu_sh, gpu_irr, stats);
    ASSERT_TRUE(st) << st.message();
    ASSERT_EQ(gpu_sh.size(), cpu_sh.size());
    const size_t values = size_t(kernels::sh_coefficient_count(c.sh_order)) * 3;
    const double sh_rel = max_relative(gpu_sh, cpu_sh, values);
    const double irr_rel = max_relative(gpu_irr, cpu_irr, kIrradianceTexels * kIrradianceTexels * 3);
    EXPECT_LE(sh_rel, 1e-5);
    EXPECT_LE(irr_rel, 1e-5);
    std::printf("order %d, %d bounces: SH within %.3g, texels within %.3g (relative), %u submission(s)\n", c.sh_order,
                c.bounces, sh_rel, irr_rel, stats.submissions);
    for (size_t p = 0; p < in.inactive.size(); ++p) {  // inactive probes hold zero once a pass ran
      if (!in.inactive[p] || c.bounces == 0) continue;
      for (size_t k = 0; k < values; ++k) {
        ASSERT_EQ(gpu_sh[p * values + k], 0.f);
      }
    }
    if (c.bounces > 0) {
      EXPECT_EQ(stats.submissions, 1u);  // everything resident: one submission
    }
    // Deterministic, and the same bytes when the hits stream through small chunks.
    std::vector<float> again_sh, again_irr = in.irradiance, chunk_sh, chunk_irr = in.irradiance;
    GpuBounceStats again_stats, chunk_stats;
    ASSERT_TRUE(run_bounce_passes_gpu(*vk, in.bi, again_sh, again_irr, again_stats));
    GpuBounceOptions small;
    small.chunk_hits = 1000;
    ASSERT_TRUE(run_bounce_passes_gpu(*vk, in.bi, chunk_sh, chunk_irr, chunk_stats, small));
    if (c.bounces > 0) {
      EXPECT_GT(chunk_stats.chunks, 5u);
    }
    for (const auto* v : {&again_sh, &chunk_sh}) EXPECT_EQ(std::memcmp(v->data(), gpu_sh.data(), gpu_sh.size() * 4), 0);
    for (const auto* v : {&again_irr, &chunk_irr})
      EXPECT_EQ(std::memcmp(v->data(), gpu_irr.data(), gpu_irr.size() * 4), 0);
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// A probe of more hits than one window of the pass kernel (GPU_RAY_WINDOW), past lavapipe's 65535
// loop iterations an invocation: its sums continue from window to window, as the CPU's in hit order.
TEST(GpuBounce, ProbePastTheLoopLimitMatchesCpu) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  tbb::task_arena arena(2);
  Inputs in = make_inputs(11, 2, 2, 70000);
  in.inactive[7] = false;
  std::vector<float> cpu_sh, cpu_irr = in.irradiance, gpu_sh, gpu_irr = in.irradiance;
  BounceTimes times;
  run_bounce_passes(in.bi, arena, Context{}, cpu_sh, cpu_irr, times);
  GpuBounceStats stats;
  const Status st = run_bounce_passes_gpu(*vk, in.bi, gpu_sh, gpu_irr, stats);
  ASSERT_TRUE(st) << st.message();
  const double sh_rel = max_relative(gpu_sh, cpu_sh, 27);
  const double irr_rel = max_relative(gpu_irr, cpu_irr, kIrradianceTexels * kIrradianceTexels * 3);
  EXPECT_LE(sh_rel, 1e-5);
  EXPECT_LE(irr_rel, 1e-5);
  std::printf("a probe of 70000 hits: SH within %.3g, texels within %.3g (relative)\n", sh_rel, irr_rel);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// What does not fit the device's memory fails first, naming the bytes.
TEST(GpuBounce, RefusesWhatDoesNotFit) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  Inputs in = make_inputs(3, 2, 2);
  std::vector<float> sh, irr = in.irradiance;
  GpuBounceStats stats;
  GpuBounceOptions tiny;
  tiny.memory_limit = 100000;  // less than the depth tiles alone
  const Status st = run_bounce_passes_gpu(*vk, in.bi, sh, irr, stats, tiny);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("bytes of device memory"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace gibake
