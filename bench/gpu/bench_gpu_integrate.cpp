// Achieved bandwidth of the integration kernel (integrate.comp): random probe rays (uniform
// directions, depths, a quarter dark), integrated into SH, irradiance texels and depth moments;
// reports the kernel time from timestamp queries and bytes moved (samples and probe table read,
// outputs written) / kernel time, best of `runs`, beside one CPU core running the CPU twin.
// Lavapipe's figures measure a CPU device, not a GPU. Vulkan alone, like bench_gpu_trace_run.
// Usage: bench_gpu_integrate [device index|name|lavapipe] [probes] [rays per probe] [runs]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <string>

#include "bake/vulkan/integrate.h"
#include "bench/gpu/pick_device.h"
#include "io/results/ddgi_result.h"
#include "kernels/sh.h"
#include "io/timer.h"

using namespace gibake;

namespace {

std::vector<kernels::RaySample> random_samples(size_t n) {
  std::mt19937 rng(5);
  std::normal_distribution<float> g(0.f, 1.f);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<kernels::RaySample> s(n);
  for (auto& r : s) {
    const kernels::float3 d = kernels::normalize(kernels::float3{g(rng), g(rng), g(rng)});
    const bool dark = u(rng) < 0.25f;
    r = {{d.x, d.y, d.z, 10.f * u(rng)}, {dark ? 0.f : u(rng), dark ? 0.f : u(rng), dark ? 0.f : u(rng), 0.f}};
  }
  return s;
}

// One CPU core over the first `probes` probes: seconds per probe.
double cpu_seconds_per_probe(const std::vector<kernels::RaySample>& s, uint32_t rays, uint32_t probes) {
  const std::vector<float> dirs = kernels::oct_tile_directions(kIrradianceTexels);
  const kernels::DepthConeTable cone = kernels::build_depth_cone_table(kDepthTexels);
  std::vector<float> sh(27), irr(192), depth(512);
  const Stopwatch timer;
  for (uint32_t p = 0; p < probes; ++p) {
    kernels::integrate_radiance(dirs.data(), kIrradianceTexels, &s[size_t(p) * rays], int(rays), 2, sh.data(),
                                irr.data());
    kernels::integrate_depth(cone, &s[size_t(p) * rays], int(rays), depth.data());
  }
  return timer.seconds() / probes;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string want = argc > 1 ? argv[1] : "";
  const uint32_t probes = argc > 2 ? uint32_t(std::stoul(argv[2])) : 4096;
  const uint32_t rays = argc > 3 ? uint32_t(std::stoul(argv[3])) : 256;
  const int runs = argc > 4 ? std::stoi(argv[4]) : 3;
  std::unique_ptr<vk::Context> vk;
  std::unique_ptr<GpuIntegrator> gi;
  Status st = bench::open_device(want, vk);
  if (st) st = GpuIntegrator::create(*vk, 2, gi, uint64_t(probes) * rays, std::min<uint32_t>(probes, 65535));
  if (!st) {
    std::fprintf(stderr, "%s\n", st.message().c_str());
    return 4;
  }
  const std::vector<kernels::RaySample> samples = random_samples(size_t(probes) * rays);
  const std::vector<uint32_t> counts(probes, rays);
  GpuIntegrateResult out;
  double best = 1e30;
  uint64_t bytes = 0;
  for (int r = 0; r <= runs; ++r) {  // the first run warms up
    const double s0 = gi->kernel_seconds();
    const uint64_t b0 = gi->kernel_bytes();
    if (!(st = gi->integrate(samples.data(), counts, out))) {
      std::fprintf(stderr, "%s\n", st.message().c_str());
      return 4;
    }
    if (r > 0 && gi->kernel_seconds() - s0 < best) best = gi->kernel_seconds() - s0;
    bytes = gi->kernel_bytes() - b0;
  }
  const double cpu = cpu_seconds_per_probe(samples, rays, std::min<uint32_t>(probes, 512));
  std::printf("device: %s (%s)\n", vk->device().name.c_str(), vk->device().driver.c_str());
  std::printf(
      "integrate.comp: %u probes x %u rays, %.1f MB moved, kernel %.3f ms (best of %d): %.2f GB/s, "
      "%.1f k probes/s\n",
      probes, rays, bytes / 1e6, best * 1e3, runs, bytes / best / 1e9, probes / best / 1e3);
  std::printf("CPU twin, one core: %.3f ms per 1000 probes (%.1f k probes/s)\n", cpu * 1e6, 1e-3 / cpu);
  return 0;
}
