// The probe-feedback bounce kernels (bounce_weights.comp, bounce_pass.comp): random bouncing hits
// in a probe grid (uniform directions, hits 0.2-2 cells away, random normals facing the ray,
// albedo, depth moments from a constant distance with a variance, a tenth of the probes
// inactive); reports the device time of the weights kernel and of the passes from timestamp
// queries, best of `runs` after a warm-up, beside one CPU core running the CPU twins
// (ddgi_probe_weights, then per pass ddgi_irradiance_from_weights, shade_indirect,
// integrate_radiance). Lavapipe's figures measure a CPU device, not a GPU. Vulkan alone.
// Usage: bench_gpu_bounce [device index|name|lavapipe] [probes per axis] [hits per probe] [passes] [runs]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>

#include "bake/vulkan/bounce.h"
#include "bench/gpu/pick_device.h"
#include "io/results/ddgi_result.h"
#include "kernels/integrate.h"
#include "kernels/sh.h"
#include "kernels/shade.h"
#include "io/timer.h"

using namespace gibake;

namespace {

using kernels::float3;
constexpr int kTile = kDepthTexels + 2;

struct Inputs {
  std::vector<float> positions, depth_tiles, sh0, irradiance, texel_dirs;
  std::vector<uint8_t> inactive;
  std::vector<uint32_t> probe_rays;
  std::vector<std::vector<BounceHit>> hits;
  BounceInputs bi;
};

Inputs make_inputs(int axis, uint32_t hits, int passes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  Inputs in;
  const int n = axis * axis * axis;
  in.positions.resize(size_t(n) * 3);
  in.depth_tiles.resize(size_t(n) * kTile * kTile * 2);
  for (size_t i = 0; i < in.depth_tiles.size(); i += 2) {
    in.depth_tiles[i] = 1.f + u(rng);
    in.depth_tiles[i + 1] = in.depth_tiles[i] * in.depth_tiles[i] * 1.01f;
  }
  in.inactive.resize(n);
  in.probe_rays.assign(n, hits + hits / 4);
  in.hits.resize(n);
  in.sh0.resize(size_t(n) * 27);
  for (float& v : in.sh0) v = u(rng);
  in.irradiance.assign(size_t(n) * kIrradianceTexels * kIrradianceTexels * 3, 1.f);
  for (int p = 0; p < n; ++p) {
    const int c[3] = {p % axis, (p / axis) % axis, p / (axis * axis)};
    for (int a = 0; a < 3; ++a) in.positions[p * 3 + a] = float(c[a]);
    in.inactive[p] = u(rng) < 0.1f;
    in.hits[p].resize(hits);
    for (BounceHit& h : in.hits[p]) {
      const float3 d = kernels::normalize(float3{g(rng), g(rng), g(rng)});
      float3 nn = kernels::normalize(float3{g(rng), g(rng), g(rng)});
      if (kernels::dot(nn, d) > 0.f) nn = -nn;
      h = BounceHit{{d.x, d.y, d.z, 0.2f + 1.8f * u(rng)}, {nn.x, nn.y, nn.z}, {u(rng), u(rng), u(rng)}};
    }
  }
  in.texel_dirs = kernels::oct_tile_directions(kIrradianceTexels);
  for (int a = 0; a < 3; ++a) {
    in.bi.volume.spacing[a] = 1.f;
    in.bi.volume.counts[a] = axis;
  }
  in.bi.volume.inactive = in.inactive.data();
  in.bi.volume.depth_tiles = in.depth_tiles.data();
  in.bi.volume.depth_res = kDepthTexels;
  in.bi.positions = in.positions.data();
  in.bi.sh0 = &in.sh0;
  in.bi.hits = &in.hits;
  in.bi.probe_rays = in.probe_rays.data();
  in.bi.texel_dirs = in.texel_dirs.data();
  in.bi.bounces = passes;
  return in;
}

// One CPU core, the first `probes` probes: seconds per probe for the weights and for one pass.
void cpu_seconds_per_probe(const Inputs& in, int probes, double& weights_s, double& pass_s) {
  std::vector<kernels::ProbeWeights> w;
  auto t0 = Clock::now();
  for (int p = 0; p < probes; ++p)
    for (const BounceHit& h : in.hits[p]) {
      const float3 hit = kernels::load3(&in.positions[p * 3]) + kernels::load3(h.dir_t) * h.dir_t[3];
      w.push_back(kernels::ddgi_probe_weights(in.bi.volume, hit, kernels::load3(h.normal)));
    }
  auto t1 = Clock::now();
  std::vector<kernels::RaySample> rs;
  float sh[27], irr[192];
  size_t i = 0;
  for (int p = 0; p < probes; ++p) {
    rs.resize(in.hits[p].size());
    for (size_t r = 0; r < rs.size(); ++r, ++i) {
      const BounceHit& h = in.hits[p][r];
      for (int a = 0; a < 4; ++a) rs[r].dir_depth[a] = h.dir_t[a];
      const float3 e = kernels::ddgi_irradiance_from_weights(in.sh0.data(), 2, w[i], kernels::load3(h.normal));
      kernels::store3(rs[r].radiance, kernels::shade_indirect(kernels::load3(h.albedo), e, 1.f));
    }
    kernels::integrate_radiance(in.texel_dirs.data(), kIrradianceTexels, rs.data(), int(rs.size()), 2, sh, irr);
  }
  auto t2 = Clock::now();
  weights_s = std::chrono::duration<double>(t1 - t0).count() / probes;
  pass_s = std::chrono::duration<double>(t2 - t1).count() / probes;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string want = argc > 1 ? argv[1] : "";
  const int axis = argc > 2 ? std::stoi(argv[2]) : 16;
  const uint32_t hits = argc > 3 ? uint32_t(std::stoul(argv[3])) : 192;
  const int passes = argc > 4 ? std::stoi(argv[4]) : 4;
  const int runs = argc > 5 ? std::stoi(argv[5]) : 3;
  std::unique_ptr<vk::Context> vk;
  Status st = bench::open_device(want, vk);
  const Inputs in = make_inputs(axis, hits, passes);
  double best_w = 1e30, best_p = 1e30;
  GpuBounceStats stats;
  for (int r = 0; st && r <= runs; ++r) {  // the first run warms up
    std::vector<float> sh, irr = in.irradiance;
    stats = GpuBounceStats();
    st = run_bounce_passes_gpu(*vk, in.bi, sh, irr, stats);
    if (r > 0) best_w = std::min(best_w, stats.weights_seconds), best_p = std::min(best_p, stats.pass_seconds);
  }
  if (!st) {
    std::fprintf(stderr, "%s\n", st.message().c_str());
    return 4;
  }
  const int probes = axis * axis * axis;
  double cpu_w = 0.0, cpu_p = 0.0;
  cpu_seconds_per_probe(in, std::min(probes, 256), cpu_w, cpu_p);
  const double total_hits = double(probes) * hits;
  std::printf("device: %s (%s)\n", vk->device().name.c_str(), vk->device().driver.c_str());
  std::printf("bounce kernels: %d probes x %u hits, %d passes, %u chunk(s), %.1f MB on the device (best of %d)\n",
              probes, hits, passes, stats.chunks, stats.device_bytes / 1e6, runs);
  std::printf("  weights %.3f ms (%.1f M hits/s), passes %.3f ms (%.1f M hit-passes/s)\n", best_w * 1e3,
              total_hits / best_w / 1e6, best_p * 1e3, total_hits * passes / best_p / 1e6);
  std::printf("CPU twins, one core: weights %.3f ms, one pass %.3f ms per 1000 probes\n", cpu_w * 1e6, cpu_p * 1e6);
  return 0;
}
