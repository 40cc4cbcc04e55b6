// DDGI trace efficiency, all in one process:
//  (a)  raw Embree throughput for exactly the bake's rays: an untimed bake first records every
//       ray it traces (relocation rays, probe rays, shadow rays: origin, direction, tnear, tfar),
//       then those rays are traced with plain rtcIntersect1 / rtcOccluded1 in a TBB parallel_for
//       over the probes (same arena size, same Embree scene flags and build quality);
//  (a') the same plus the Embree scene build, timed separately;
//  (b)  the bake's effective rate: all rays it traced / the whole bake_ddgi wall time (grid,
//       Embree build, relocation, tracing, shading, depth moments, classification incl. the CGAL
//       closed-mesh check, every bounce pass, atlases).
// Target (b)/(a) >= 0.85. GIBAKE_BENCH_DUMP=file writes the result arrays (to compare builds).
// Usage: bench_ddgi_trace [scene.gltf] [threads] [rays] [closed-mesh-check on|off]
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bake/ddgi.h"
#include "bake/prepare.h"
#include "bake/probe_grid.h"
#include "io/import.h"
#include "bake/ray_capture.h"

using namespace gibake;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : GIBAKE_ASSETS_DIR "/reciprocating-saw/ReciprocatingSaw.gltf";
  const unsigned threads = argc > 2 ? static_cast<unsigned>(std::stoul(argv[2])) : 0;
  const uint32_t rays = argc > 3 ? static_cast<uint32_t>(std::stoul(argv[3])) : 256;
  Context ctx;
  ctx.threads = threads;
  Scene scene;
  if (Status st = import_scene(path, ImportOptions{}, ctx, scene); !st) {
    std::fprintf(stderr, "import failed: %s\n", st.message().c_str());
    return 1;
  }
  DdgiSettings s;
  s.rays = rays;
  s.suns.push_back(SunLight{{0.3f, -1.f, 0.2f}, 1000.f, {1, 1, 1}});
  s.sky = {0.2f, 0.3f, 0.5f};
  s.cgal_check = !(argc > 4 && std::string(argv[4]) == "off");
  // Untimed run that records every ray the bake traces (relocation, probe and shadow rays, with
  // their exact origins, directions and [tnear, tfar]); it also warms caches and the allocator.
  RayCapture captured;
  {
    DdgiSettings cs = s;
    cs.capture_rays = &captured;
    DdgiResult r;
    DdgiReport rep;
    if (Status st = bake_ddgi(scene, cs, ctx, r, rep); !st) {
      std::fprintf(stderr, "bake failed: %s\n", st.message().c_str());
      return 1;
    }
  }
  DdgiResult result;
  DdgiReport report;
  const auto t0 = Clock::now();
  if (Status st = bake_ddgi(scene, s, ctx, result, report); !st) {
    std::fprintf(stderr, "bake failed: %s\n", st.message().c_str());
    return 1;
  }
  const double bake_s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (const char* dump = std::getenv("GIBAKE_BENCH_DUMP")) {
    FILE* f = std::fopen(dump, "wb");
    auto put = [&](const void* d, size_t n) { if (n) std::fwrite(d, 1, n, f); };
    put(result.sh.data(), result.sh.size() * 4);
    put(result.irradiance_atlas.data(), result.irradiance_atlas.size() * 4);
    put(result.depth_atlas.data(), result.depth_atlas.size() * 4);
    put(result.offsets.data(), result.offsets.size() * 4);
    put(result.states.data(), result.states.size());
    put(result.stats.data(), result.stats.size() * sizeof(DdgiProbeStats));
    std::fclose(f);
  }

  // (a) The captured rays through plain Embree calls: a fresh scene build (same flags and build
  // quality as the bake's, outside the arena like the bake's), then one tbb::parallel_for over
  // the probes (grain 2, as the bake) calling rtcIntersect1 / rtcOccluded1 per ray.
  const auto tb = Clock::now();
  std::unique_ptr<PreparedScene> prepared;
  if (!PreparedScene::create(scene, ctx, prepared)) return 1;
  const double build_s = std::chrono::duration<double>(Clock::now() - tb).count();
  auto rtc = static_cast<RTCScene>(prepared->rtc_scene());
  const int32_t probes = result.desc.probe_count();
  tbb::task_arena arena = threads ? tbb::task_arena(static_cast<int>(threads)) : tbb::task_arena();
  std::atomic<uint64_t> traced{0}, shadow{0};
  std::atomic<uint64_t> sink{0};
  const auto t1 = Clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, probes, 2), [&](const tbb::blocked_range<int32_t>& r) {
      uint64_t count = 0, occl = 0, hits = 0;
      for (int32_t p = r.begin(); p != r.end(); ++p) {
        for (const CapturedRay& cr : captured[p]) {
          RTCIntersectContext ic;
          rtcInitIntersectContext(&ic);
          ++count;
          if (cr.occlusion) {
            RTCRay ray{};
            ray.org_x = cr.org[0]; ray.org_y = cr.org[1]; ray.org_z = cr.org[2];
            ray.dir_x = cr.dir[0]; ray.dir_y = cr.dir[1]; ray.dir_z = cr.dir[2];
            ray.tnear = cr.tnear;
            ray.tfar = cr.tfar;
            ray.mask = 0xFFFFFFFFu;
            rtcOccluded1(rtc, &ic, &ray);
            ++occl;
            hits += ray.tfar < 0.f;
          } else {
            RTCRayHit rh{};
            rh.ray.org_x = cr.org[0]; rh.ray.org_y = cr.org[1]; rh.ray.org_z = cr.org[2];
            rh.ray.dir_x = cr.dir[0]; rh.ray.dir_y = cr.dir[1]; rh.ray.dir_z = cr.dir[2];
            rh.ray.tnear = cr.tnear;
            rh.ray.tfar = cr.tfar;
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(rtc, &ic, &rh);
            hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
          }
        }
      }
      traced += count;
      shadow += occl;
      sink += hits;
    });
  });
  const double raw_s = std::chrono::duration<double>(Clock::now() - t1).count();
  const double raw_rate = traced / raw_s;
  const double raw_build_rate = traced / (raw_s + build_s);
  const double bake_rate = report.total_rays() / bake_s;
  std::printf("scene: %s\n", path.c_str());
  std::printf("triangles: %zu, probes: %d (%dx%dx%d), rays/probe: %u, threads: %u\n", scene.triangle_count(), probes,
              result.desc.counts[0], result.desc.counts[1], result.desc.counts[2], rays, threads);
  std::printf("bake: %.3f s wall, %llu rays (%llu primary, %llu shadow, %llu relocation)\n", bake_s,
              static_cast<unsigned long long>(report.total_rays()), static_cast<unsigned long long>(report.primary_rays),
              static_cast<unsigned long long>(report.shadow_rays),
              static_cast<unsigned long long>(report.relocation_rays));
  for (const auto& [stage, sec] : report.stage_seconds) std::printf("  %-10s %.3f s\n", stage.c_str(), sec);
  std::printf("closed-mesh check: %s (checked %d, inside %u, disagreements %u, inactive outside closed %u)\n",
              s.cgal_check ? "on" : "off", int(report.cgal_checked), report.cgal_inside, report.cgal_disagreements,
              report.cgal_inactive_outside);
  std::printf("probes: %d active, %d inactive, %d relocated; bouncing hits %llu\n", report.active, report.inactive,
              report.relocated, static_cast<unsigned long long>(report.bounce_hits));
  std::printf("(a) raw Embree, captured rays: %llu (%llu occlusion), %llu hit; build %.3f s, trace %.3f s\n",
              static_cast<unsigned long long>(traced.load()), static_cast<unsigned long long>(shadow.load()),
              static_cast<unsigned long long>(sink.load()), build_s, raw_s);
  std::printf("(a)  trace only        : %.3f Mrays/s\n", raw_rate / 1e6);
  std::printf("(a') build + trace     : %.3f Mrays/s\n", raw_build_rate / 1e6);
  std::printf("(b) bake effective     : %.3f Mrays/s (whole bake_ddgi, BVH build included)\n", bake_rate / 1e6);
  std::printf("(b)/(a)  = %.3f (target >= 0.85)\n", bake_rate / raw_rate);
  std::printf("(b)/(a') = %.3f (both sides include the BVH build)\n", bake_rate / raw_build_rate);
  if (traced.load() != report.total_rays()) std::printf("WARNING: captured ray count differs from the bake's\n");
  return 0;
}
