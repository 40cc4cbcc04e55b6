// Probe ray generation on lavapipe (raygen.comp) against its CPU twin, generate_probe_rays_from_set
// + make_path_rays. Required: origins and keys rng_hash(seed, probe, pass, ray) bit-identical, every
// direction component within 1e-6 (the kernel repeats the CPU's operations in order; only a device's
// sqrt or division may round differently), and the unused words zero. Covers chunks split over
// several dispatches at arbitrary ray offsets, set sizes that are not multiples of the workgroup,
// a one-ray set, 64-bit seeds and large probe and pass numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "bake/vulkan/path.h"
#include "bake/vulkan/raygen.h"
#include "kernels/ray_gen.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

struct Probe {
  kernels::float3 pos;
  uint32_t index, pass;
};

std::vector<Probe> random_probes(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-50.f, 50.f);
  std::vector<Probe> v;
  for (size_t i = 0; i < n; ++i)
    v.push_back(
        {{u(rng), u(rng), u(rng)}, uint32_t(rng() % 40000u) + (i == 0 ? 0xFFFF0000u : 0u), uint32_t(rng() % 9u)});
  return v;
}

// The CPU's rays of a chunk, probe after probe.
std::vector<gpu::GpuPathRay> cpu_rays(const std::vector<Probe>& probes, const std::vector<float>& fib, uint32_t n,
                                      uint64_t seed) {
  std::vector<gpu::GpuPathRay> out(probes.size() * n);
  std::vector<float> dirs(size_t(n) * 3);
  for (size_t i = 0; i < probes.size(); ++i) {
    kernels::generate_probe_rays_from_set(fib.data(), seed, probes[i].index, probes[i].pass, n, dirs.data());
    make_path_rays(probes[i].pos, dirs.data(), n, seed, probes[i].index, probes[i].pass, &out[i * n]);
  }
  return out;
}

// Generates the chunk on the device in dispatches of `step` rays and compares it with the CPU's.
void check(uint32_t n, size_t probe_count, uint64_t seed, uint32_t step) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  std::unique_ptr<GpuRayGen> gen;
  Status st = GpuRayGen::create(*vk, gen);
  ASSERT_TRUE(st) << st.message();
  std::vector<float> fib(size_t(n) * 3);
  kernels::spherical_fibonacci_set(n, fib.data());
  const std::vector<Probe> probes = random_probes(probe_count, uint32_t(seed));
  std::vector<gpu::GpuRayGenProbe> records;
  for (const Probe& p : probes) records.push_back(raygen_probe(p.pos, seed, p.index, p.pass));
  ASSERT_TRUE(st = gen->set_fibonacci(fib.data(), n)) << st.message();
  ASSERT_TRUE(st = gen->set_probes(records)) << st.message();
  const uint32_t total = uint32_t(probes.size() * n);
  vk::Buffer rays;
  ASSERT_TRUE(st = vk->create_buffer(uint64_t(step) * sizeof(gpu::GpuPathRay), rays, "rays")) << st.message();
  std::vector<gpu::GpuPathRay> gpu(total);
  for (uint32_t first = 0; first < total; first += step) {
    const uint32_t count = std::min(step, total - first);
    ASSERT_TRUE(st = vk->run({gen->dispatch(rays, first, count, seed)})) << st.message();
    ASSERT_TRUE(st = vk->download(rays, &gpu[first], uint64_t(count) * sizeof(gpu::GpuPathRay))) << st.message();
  }
  const std::vector<gpu::GpuPathRay> cpu = cpu_rays(probes, fib, n, seed);
  float worst = 0.f;
  size_t differing = 0;
  for (uint32_t i = 0; i < total; ++i) {
    const gpu::GpuPathRay &a = gpu[i], &b = cpu[i];
    ASSERT_EQ(std::memcmp(&a.org, &b.org, 16), 0) << "ray " << i << ": origin";
    ASSERT_EQ(std::memcmp(&a.key, &b.key, 16), 0) << "ray " << i << ": key";
    const float da[4] = {a.dir.x, a.dir.y, a.dir.z, a.dir.w}, db[3] = {b.dir.x, b.dir.y, b.dir.z};
    EXPECT_EQ(da[3], 0.f);
    for (int c = 0; c < 3; ++c) {
      const float d = std::fabs(da[c] - db[c]);
      EXPECT_LE(d, 1e-6f) << "ray " << i << " component " << c << ": " << da[c] << " vs " << db[c];
      worst = std::max(worst, d);
      differing += da[c] != db[c];
    }
  }
  std::printf(
      "%u rays x %zu probes, dispatches of %u: largest direction difference %.3g, %zu of %u components differ\n", n,
      probes.size(), step, worst, differing, total * 3);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

TEST(GpuRayGen, MatchesCpuTwin) { check(256, 37, 0, 1u << 19); }
// Dispatches that start and end inside probes, and 64-bit seeds.
TEST(GpuRayGen, SplitDispatches) { check(77, 53, 0x9E3779B97F4A7C15ull, 1000); }
TEST(GpuRayGen, ManyRaysAndOneRay) {
  check(1000, 9, 12345, 4096);
  check(1, 100, 7, 33);
}

// The lanes' order of a probe's rays (no device): each block a permutation of its own rays, the
// identity for a block of 1 or one that does not divide the set, and neighbouring lanes at least
// four times closer in direction than neighbouring rays of the Fibonacci order (the test prints
// both mean angles).
TEST(GpuRayGen, LaneOrderKeepsBlocksAndBringsNeighboursTogether) {
  const uint32_t n = 2048;
  std::vector<float> set(size_t(n) * 3);
  kernels::spherical_fibonacci_set(n, set.data());
  for (const uint32_t block : {1u, 3u, 4096u}) {
    const std::vector<uint32_t> id = lane_order(set.data(), n, block);
    for (uint32_t k = 0; k < n; ++k) ASSERT_EQ(id[k], k) << "block " << block;
  }
  const std::vector<uint32_t> order = lane_order(set.data(), n, 256);
  ASSERT_EQ(order.size(), n);
  for (uint32_t first = 0; first < n; first += 256) {
    std::vector<uint32_t> b(order.begin() + first, order.begin() + first + 256);
    std::sort(b.begin(), b.end());
    for (uint32_t k = 0; k < 256; ++k) ASSERT_EQ(b[k], first + k);
  }
  const auto mean_step = [&](const std::vector<uint32_t>& o) {
    double sum = 0.0;
    for (uint32_t k = 1; k < n; ++k) {
      const float* a = &set[size_t(o[k - 1]) * 3];
      const float* b = &set[size_t(o[k]) * 3];
      sum += std::acos(std::clamp(double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2], -1.0, 1.0));
    }
    return sum / (n - 1);
  };
  const double ray_order = mean_step(lane_order(set.data(), n, 1)), lanes = mean_step(order);
  std::printf("mean angle between neighbouring lanes: %.3f rad in ray order, %.3f rad in lane order\n", ray_order,
              lanes);
  EXPECT_LT(lanes * 4.0, ray_order);
}

}  // namespace
}  // namespace gibake
