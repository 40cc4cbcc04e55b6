// Prepares the GPU traversal benchmark (bench/gpu/bench_gpu_trace_run.cpp): bakes a scene on the
// CPU recording every ray it traces (RunContext::capture_rays), keeps the rays of every k-th
// probe (about `sample` closest-hit and as many shadow rays), asks Embree for their answers, times
// Embree on them with all threads here, builds the GPU scene and writes it all to one file.
// Usage: bench_gpu_trace_dump scene.gltf out.gbtr [X,Y,Z probes] [rays] [bounces] [sample] [threads]
//        [spatial splits on|off]
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/scene/prepare.h"
#include "bake/vulkan/device_scene.h"
#include "bench/gpu/trace_dump.h"
#include "io/gltf/import.h"
#include "io/timer.h"

using namespace gibake;

namespace {


// Embree on the sampled rays, all threads: closest hits and shadow rays timed apart.
void embree_answers(const PreparedScene& ps, unsigned threads, bench::TraceDump& d) {
  tbb::task_arena arena(threads ? int(threads) : tbb::task_arena::automatic);
  d.closest_t.resize(d.closest.size());
  d.shadow_blocked.resize(d.shadow.size());
  auto t0 = Clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, d.closest.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const auto& ray = d.closest[i];
        const TraceHit h = ps.intersect({ray.org_tmin.x, ray.org_tmin.y, ray.org_tmin.z},
                                        {ray.dir_tmax.x, ray.dir_tmax.y, ray.dir_tmax.z}, ray.org_tmin.w, ray.dir_tmax.w);
        d.closest_t[i] = h.t;
      }
    });
  });
  const double tc = seconds_since(t0);
  t0 = Clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, d.shadow.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const auto& ray = d.shadow[i];
        d.shadow_blocked[i] = ps.occluded({ray.org_tmin.x, ray.org_tmin.y, ray.org_tmin.z},
                                          {ray.dir_tmax.x, ray.dir_tmax.y, ray.dir_tmax.z}, ray.org_tmin.w,
                                          ray.dir_tmax.w);
      }
    });
  });
  const double ts = seconds_since(t0);
  const int n = arena.max_concurrency();
  std::printf("Embree here (%d threads): closest hit %.2f Mrays/s (%.2f per thread), shadow %.2f Mrays/s (%.2f per "
              "thread)\n",
              n, d.closest.size() / tc / 1e6, d.closest.size() / tc / 1e6 / n, d.shadow.size() / ts / 1e6,
              d.shadow.size() / ts / 1e6 / n);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s scene.gltf out.gbtr [X,Y,Z] [rays] [bounces] [sample] [threads]\n", argv[0]);
    return 1;
  }
  const std::string counts = argc > 3 ? argv[3] : "32,15,21";
  const uint32_t rays = argc > 4 ? uint32_t(std::stoul(argv[4])) : 256;
  const int bounces = argc > 5 ? std::stoi(argv[5]) : 4;
  const size_t sample = argc > 6 ? std::stoul(argv[6]) : 600000;
  Context ctx;
  ctx.threads = argc > 7 ? unsigned(std::stoul(argv[7])) : 0;
  const PipelineDevices platform;
  Scene scene;
  if (Status st = import_scene(argv[1], {}, ctx, scene); !st) return std::fprintf(stderr, "%s\n", st.message().c_str()), 1;
  DdgiSettings s;
  std::sscanf(counts.c_str(), "%d,%d,%d", &s.grid.counts[0], &s.grid.counts[1], &s.grid.counts[2]);
  s.rays = rays;
  s.bounces = bounces;
  s.suns.push_back(SunLight{{0.3f, -1.f, 0.2f}, 100000.f, {1, 1, 1}});
  RayCapture captured;
  RunContext capture_run;
  capture_run.platform = &platform;
  capture_run.capture_rays = &captured;
  DdgiResult result;
  DdgiReport report;
  auto t0 = Clock::now();
  if (Status st = bake_ddgi(scene, s, capture_run, ctx, result, report); !st) return std::fprintf(stderr, "%s\n", st.message().c_str()), 1;
  std::printf("CPU bake with ray capture: %.2f s, %d probes, %llu rays\n", seconds_since(t0), report.probes,
              (unsigned long long)report.total_rays());
  size_t total_closest = 0, total_shadow = 0;
  for (const auto& list : captured)
    for (const auto& r : list) (r.kind == CapturedRay::kShadow ? total_shadow : total_closest)++;
  const size_t stride = std::max<size_t>(1, total_closest / std::max<size_t>(1, sample));
  bench::TraceDump d;
  for (size_t p = 0; p < captured.size(); p += stride)
    for (const auto& r : captured[p]) {
      const gpu::GpuRay g{{r.org[0], r.org[1], r.org[2], r.tnear}, {r.dir[0], r.dir[1], r.dir[2], r.tfar}};
      (r.kind == CapturedRay::kShadow ? d.shadow : d.closest).push_back(g);
    }
  char note[512];
  std::snprintf(note, sizeof(note),
                "%s: %d probes (%s) x %u rays, %d bounces, sun 0.3,-1,0.2:100000; the rays of every %zu-th probe "
                "(%zu of %zu closest-hit, %zu of %zu shadow)",
                argv[1], report.probes, counts.c_str(), rays, bounces, stride, d.closest.size(), total_closest,
                d.shadow.size(), total_shadow);
  d.note = note;
  std::printf("%s\n", note);
  std::unique_ptr<PreparedScene> ps;
  if (Status st = PreparedScene::create(scene, ctx, ps); !st) return 1;
  embree_answers(*ps, ctx.threads, d);
  t0 = Clock::now();
  GpuSceneOptions options;
  options.spatial_splits = !(argc > 8 && std::string(argv[8]) == "off");
  if (Status st = build_gpu_scene(scene, options, ctx, d.scene); !st) return std::fprintf(stderr, "%s\n", st.message().c_str()), 1;
  std::printf("GPU BVH: %.2f s, %zu nodes, %zu triangle references, depth %u, %.1f bytes per triangle\n", seconds_since(t0),
              d.scene.nodes.size(), d.scene.triangles.size(), d.scene.depth, d.scene.bvh_bytes_per_triangle());
  if (!bench::write_dump(argv[2], d)) return std::fprintf(stderr, "cannot write %s\n", argv[2]), 2;
  return 0;
}
