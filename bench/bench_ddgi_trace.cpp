// DDGI trace efficiency: (a) raw Embree throughput for the bake's rays (primary probe rays,
// relocation rays and sun shadow rays, regenerated from the baked probe positions and traced with
// plain rtcIntersect1 / rtcOccluded1 in a TBB loop) against (b) the bake's effective rate,
// all rays traced / whole bake_ddgi wall time. Target (b)/(a) >= 0.85.
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
#include <string>
#include <vector>

#include "bake/ddgi.h"
#include "bake/prepare.h"
#include "bake/probe_grid.h"
#include "io/import.h"
#include "kernels/ray_gen.h"

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
  DdgiResult result;
  DdgiReport report;
  const auto t0 = Clock::now();
  if (Status st = bake_ddgi(scene, s, ctx, result, report); !st) {
    std::fprintf(stderr, "bake failed: %s\n", st.message().c_str());
    return 1;
  }
  const double bake_s = std::chrono::duration<double>(Clock::now() - t0).count();

  // (a) Same kinds and counts of rays through plain Embree calls.
  std::unique_ptr<PreparedScene> prepared;
  if (!PreparedScene::create(scene, ctx, prepared)) return 1;
  auto rtc = static_cast<RTCScene>(prepared->rtc_scene());
  const int32_t probes = result.desc.probe_count();
  float sun[3] = {-0.3f, 1.f, -0.2f};
  const float len = std::sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]);
  for (float& c : sun) c /= len;
  tbb::task_arena arena = threads ? tbb::task_arena(static_cast<int>(threads)) : tbb::task_arena();
  std::atomic<uint64_t> traced{0};
  const auto t1 = Clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, probes, 2), [&](const tbb::blocked_range<int32_t>& r) {
      std::vector<float> dirs;
      uint64_t count = 0;
      for (int32_t p = r.begin(); p != r.end(); ++p) {
        const auto rest = probe_rest_position(result.desc, p);
        const float org[3] = {rest[0] + result.offsets[p * 3], rest[1] + result.offsets[p * 3 + 1],
                              rest[2] + result.offsets[p * 3 + 2]};
        // Relocation passes (2 x relocate_rays) and the bake batch (rays), as the bake traces them.
        for (int pass = 0; pass < 3; ++pass) {
          const uint32_t n = pass < 2 ? s.relocate_rays : s.rays;
          dirs.resize(n * 3);
          kernels::generate_probe_rays(s.seed, p, pass < 2 ? 0x40000000u + pass : 0u, n, dirs.data());
          for (uint32_t i = 0; i < n; ++i) {
            RTCIntersectContext ic;
            rtcInitIntersectContext(&ic);
            RTCRayHit rh{};
            rh.ray.org_x = org[0]; rh.ray.org_y = org[1]; rh.ray.org_z = org[2];
            rh.ray.dir_x = dirs[i * 3]; rh.ray.dir_y = dirs[i * 3 + 1]; rh.ray.dir_z = dirs[i * 3 + 2];
            rh.ray.tfar = std::numeric_limits<float>::infinity();
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(rtc, &ic, &rh);
            ++count;
            if (pass < 2 || rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
            const float ndl = rh.hit.Ng_x * sun[0] + rh.hit.Ng_y * sun[1] + rh.hit.Ng_z * sun[2];
            const float ndd = rh.hit.Ng_x * rh.ray.dir_x + rh.hit.Ng_y * rh.ray.dir_y + rh.hit.Ng_z * rh.ray.dir_z;
            if (ndd >= 0.f || ndl <= 0.f) continue;  // back face, or facing away from the sun
            RTCRay sr{};
            sr.org_x = rh.ray.org_x + rh.ray.dir_x * rh.ray.tfar + sun[0] * 1e-3f;
            sr.org_y = rh.ray.org_y + rh.ray.dir_y * rh.ray.tfar + sun[1] * 1e-3f;
            sr.org_z = rh.ray.org_z + rh.ray.dir_z * rh.ray.tfar + sun[2] * 1e-3f;
            sr.dir_x = sun[0]; sr.dir_y = sun[1]; sr.dir_z = sun[2];
            sr.tfar = std::numeric_limits<float>::infinity();
            sr.mask = 0xFFFFFFFFu;
            rtcOccluded1(rtc, &ic, &sr);
            ++count;
          }
        }
      }
      traced += count;
    });
  });
  const double raw_s = std::chrono::duration<double>(Clock::now() - t1).count();
  const double raw_rate = traced / raw_s;
  const double bake_rate = report.total_rays() / bake_s;
  std::printf("scene: %s\n", path.c_str());
  std::printf("triangles: %zu, probes: %d (%dx%dx%d), rays/probe: %u, threads: %u\n", scene.triangle_count(), probes,
              result.desc.counts[0], result.desc.counts[1], result.desc.counts[2], rays, threads);
  std::printf("bake: %.3f s wall, %llu rays (%llu primary, %llu shadow, %llu relocation)\n", bake_s,
              static_cast<unsigned long long>(report.total_rays()), static_cast<unsigned long long>(report.primary_rays),
              static_cast<unsigned long long>(report.shadow_rays),
              static_cast<unsigned long long>(report.relocation_rays));
  for (const auto& [stage, sec] : report.stage_seconds) std::printf("  %-10s %.3f s\n", stage.c_str(), sec);
  std::printf("closed-mesh check: %s\n", s.cgal_check ? "on" : "off");
  std::printf("(a) raw Embree: %llu rays in %.3f s = %.3f Mrays/s\n", static_cast<unsigned long long>(traced.load()),
              raw_s, raw_rate / 1e6);
  std::printf("(b) bake effective: %.3f Mrays/s\n", bake_rate / 1e6);
  std::printf("(b)/(a) = %.3f (target >= 0.85)\n", bake_rate / raw_rate);
  return 0;
}
