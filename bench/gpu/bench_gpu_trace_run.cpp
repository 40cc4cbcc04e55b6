// GPU traversal throughput on a bake's own rays (the file bench_gpu_trace_dump writes): checks the
// device's answers against Embree's, then times closest-hit and shadow rays apart (kernel time
// from timestamp queries, and wall time with the ray/hit transfers), the sample tiled to `rays`.
// Usage: bench_gpu_trace_run file.gbtr [device index|name|lavapipe] [rays per run] [runs] [batch]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "bake/vulkan/traverse.h"
#include "bench/gpu/pick_device.h"
#include "bench/gpu/trace_dump.h"
#include "io/timer.h"

using namespace gibake;

namespace {

using bench::pick_device;

std::vector<gpu::GpuRay> tile(const std::vector<gpu::GpuRay>& sample, size_t n) {
  std::vector<gpu::GpuRay> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = sample[i % sample.size()];
  return out;
}

// Best of `runs` (after a warm-up): kernel seconds and wall seconds for one pass over `rays`.
template <class F>
void time_runs(int runs, F&& pass, double& kernel, double& wall) {
  kernel = wall = 1e30;
  for (int r = 0; r <= runs; ++r) {
    double k = 0.0;
    const Stopwatch timer;
    if (!pass(k)) return;
    const double w = timer.seconds();
    if (r == 0) continue;  // warm-up
    kernel = std::min(kernel, k);
    wall = std::min(wall, w);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return std::fprintf(stderr, "usage: %s file.gbtr [device] [rays] [runs] [batch]\n", argv[0]), 1;
  bench::TraceDump d;
  if (!bench::read_dump(argv[1], d)) return std::fprintf(stderr, "cannot read %s\n", argv[1]), 2;
  const std::string want = argc > 2 ? argv[2] : "";
  const size_t n = argc > 3 ? std::stoul(argv[3]) : size_t(1) << 24;
  const int runs = argc > 4 ? std::stoi(argv[4]) : 3;
  const uint32_t batch = argc > 5 ? uint32_t(std::stoul(argv[5])) : 1u << 23;
  std::vector<vk::DeviceInfo> devices;
  if (Status st = vk::list_devices(devices); !st) return std::fprintf(stderr, "%s\n", st.message().c_str()), 4;
  for (const auto& dev : devices) std::printf("device [%u] %s (%s), driver %s\n", dev.index, dev.name.c_str(), dev.type.c_str(), dev.driver.c_str());
  const int index = pick_device(devices, want);
  if (index < 0) return std::fprintf(stderr, "no such Vulkan device\n"), 4;
  std::unique_ptr<vk::Context> vk;
  vk::ContextOptions o;
  o.device_index = uint32_t(index);
  if (Status st = vk::Context::create(o, vk); !st) return std::fprintf(stderr, "%s\n", st.message().c_str()), 4;
  std::printf("using [%d] %s, driver %s\n%s\n", index, vk->device().name.c_str(), vk->device().driver.c_str(), d.note.c_str());
  std::printf("BVH: %zu nodes, %zu triangle references, depth %u, %.1f bytes per triangle (%zu triangles)\n",
              d.scene.nodes.size(), d.scene.triangles.size(), d.scene.depth, d.scene.bvh_bytes_per_triangle(),
              d.scene.scene_triangles);
  std::unique_ptr<GpuTracer> tracer;
  if (Status st = GpuTracer::create(*vk, d.scene, tracer, batch); !st) return std::fprintf(stderr, "%s\n", st.message().c_str()), 4;
  // Agreement with Embree on the sample itself.
  std::vector<gpu::GpuHit> hits;
  std::vector<uint32_t> blocked;
  if (!tracer->intersect(d.closest, hits) || !tracer->occluded(d.shadow, blocked)) return 4;
  size_t hit_miss = 0, far_t = 0, shadow_diff = 0;
  for (size_t i = 0; i < hits.size(); ++i) {
    const float e = d.closest_t[i], g = hits[i].t_tri_uv.x;
    if ((e < 0.f) != (g < 0.f)) ++hit_miss;
    else if (e >= 0.f && std::fabs(e - g) > 1e-4f * (1.f + e)) ++far_t;
  }
  for (size_t i = 0; i < blocked.size(); ++i) shadow_diff += (blocked[i] != 0) != (d.shadow_blocked[i] != 0);
  std::printf("agreement with Embree: %zu closest-hit rays, %zu hit/miss differences, %zu distances off by > 1e-4; "
              "%zu shadow rays, %zu answers differ\n",
              hits.size(), hit_miss, far_t, blocked.size(), shadow_diff);
  // Throughput.
  const auto closest = tile(d.closest, n), shadow = tile(d.shadow, n);
  double kc, wc, ks, ws;
  time_runs(runs, [&](double& k) { return bool(tracer->intersect(closest, hits, &k)); }, kc, wc);
  time_runs(runs, [&](double& k) { return bool(tracer->occluded(shadow, blocked, &k)); }, ks, ws);
  std::printf("closest hit: %zu rays, kernel %.4f s = %.3f G rays/s; wall with transfers %.4f s = %.3f G rays/s\n", n, kc,
              n / kc / 1e9, wc, n / wc / 1e9);
  std::printf("shadow     : %zu rays, kernel %.4f s = %.3f G rays/s; wall with transfers %.4f s = %.3f G rays/s\n", n, ks,
              n / ks / 1e9, ws, n / ws / 1e9);
  return 0;
}
