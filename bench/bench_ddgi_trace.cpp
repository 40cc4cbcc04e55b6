// DDGI trace efficiency, all in one process:
//  (a)  raw Embree throughput for exactly the bake's rays: an untimed bake first records every
//       ray it traces (relocation rays, probe rays, shadow rays: origin, direction, tnear, tfar),
//       then those rays are traced with plain rtcIntersect1 / rtcOccluded1 in a TBB parallel_for
//       over the probes (same arena size, same Embree scene flags and build quality);
//  (a') the same plus the Embree scene build, timed separately;
//  (b)  the bake's effective rate: all rays it traced / the whole bake_ddgi wall time (grid,
//       Embree build, relocation, tracing, shading, depth moments, classification incl. the CGAL
//       closed-mesh check, every bounce pass, atlases).
// Target (b)/(a) >= 0.85. Also printed: (a) split into relocation rays and probe + shadow rays
// next to the bake stages that trace them; the ceiling on (b)/(a) that the Embree build alone
// sets; and the probe rays through 8-wide packets and a coherent stream (sorted by direction)
// against single rays, to show whether packets/streams would help.
// GIBAKE_BENCH_DUMP=file writes the result arrays (to compare builds).
// Usage: bench_ddgi_trace [scene.gltf] [threads] [rays] [closed-mesh-check on|off] [sun lux] [path|probes]
//        [probe spacing m]
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/ddgi/probe_grid.h"
#include "bake/scene/prepare.h"
#include "bake/trace/ray_capture.h"
#include "io/gltf/import.h"
#include "io/timer.h"

using namespace gibake;

namespace {

struct RawRun {
  double seconds = 0.0;
  uint64_t rays = 0, hits = 0;
};

RTCRayHit make_rayhit(const CapturedRay& c) {
  RTCRayHit rh{};
  rh.ray.org_x = c.org[0];
  rh.ray.org_y = c.org[1];
  rh.ray.org_z = c.org[2];
  rh.ray.dir_x = c.dir[0];
  rh.ray.dir_y = c.dir[1];
  rh.ray.dir_z = c.dir[2];
  rh.ray.tnear = c.tnear;
  rh.ray.tfar = c.tfar;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// One tbb::parallel_for over the probes (grain 2, as the bake) calling `trace_probe(list)` on each
// probe's ray list; it returns the number of hits.
template <class F>
RawRun run_probes(tbb::task_arena& arena, const std::vector<std::vector<CapturedRay>>& lists, F&& trace_probe) {
  std::atomic<uint64_t> rays{0}, hits{0};
  const auto t0 = Clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, lists.size(), 2), [&](const tbb::blocked_range<size_t>& r) {
      uint64_t n = 0, h = 0;
      for (size_t p = r.begin(); p != r.end(); ++p) {
        n += lists[p].size();
        h += trace_probe(lists[p]);
      }
      rays += n;
      hits += h;
    });
  });
  return {seconds_since(t0), rays.load(), hits.load()};
}

// Plain rtcIntersect1 / rtcOccluded1, one ray at a time.
uint64_t trace_single(RTCScene scene, const std::vector<CapturedRay>& list) {
  uint64_t hits = 0;
  for (const CapturedRay& c : list) {
    RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    RTCRayHit rh = make_rayhit(c);
    if (c.kind == CapturedRay::kShadow) {
      rtcOccluded1(scene, &ic, &rh.ray);
      hits += rh.ray.tfar < 0.f;
    } else {
      rtcIntersect1(scene, &ic, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
  }
  return hits;
}

// rtcIntersect8 over the list in order (closest-hit rays only), coherent context flag.
uint64_t trace_packets8(RTCScene scene, const std::vector<CapturedRay>& list) {
  uint64_t hits = 0;
  RTCIntersectContext ic;
  rtcInitIntersectContext(&ic);
  ic.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  for (size_t i = 0; i < list.size(); i += 8) {
    alignas(32) RTCRayHit8 rh;
    alignas(32) int valid[8];
    for (int k = 0; k < 8; ++k) {
      const size_t j = std::min(i + k, list.size() - 1);
      const RTCRayHit one = make_rayhit(list[j]);
      valid[k] = i + k < list.size() ? -1 : 0;
      rh.ray.org_x[k] = one.ray.org_x; rh.ray.org_y[k] = one.ray.org_y; rh.ray.org_z[k] = one.ray.org_z;
      rh.ray.dir_x[k] = one.ray.dir_x; rh.ray.dir_y[k] = one.ray.dir_y; rh.ray.dir_z[k] = one.ray.dir_z;
      rh.ray.tnear[k] = one.ray.tnear; rh.ray.tfar[k] = one.ray.tfar; rh.ray.time[k] = 0.f;
      rh.ray.mask[k] = one.ray.mask; rh.ray.flags[k] = 0; rh.ray.id[k] = 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, scene, &ic, &rh);
    for (int k = 0; k < 8; ++k) hits += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
  }
  return hits;
}

// rtcIntersect1M over the whole list as one coherent stream (closest-hit rays only).
uint64_t trace_stream(RTCScene scene, const std::vector<CapturedRay>& list) {
  RTCIntersectContext ic;
  rtcInitIntersectContext(&ic);
  ic.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  std::vector<RTCRayHit> rays(list.size());
  for (size_t i = 0; i < list.size(); ++i) rays[i] = make_rayhit(list[i]);
  rtcIntersect1M(scene, &ic, rays.data(), static_cast<unsigned>(rays.size()), sizeof(RTCRayHit));
  uint64_t hits = 0;
  for (const RTCRayHit& rh : rays) hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  return hits;
}

// Morton order of a direction's octahedral coordinates (1024^2 cells): neighbours in the list
// are neighbours on the sphere, the most coherent order rays from one point can have.
uint32_t octahedral_morton(const float* d) {
  const float l1 = std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]);
  float x = d[0] / l1, y = d[1] / l1;
  if (d[2] < 0.f) {
    const float fx = (1.f - std::fabs(y)) * (x >= 0.f ? 1.f : -1.f);
    const float fy = (1.f - std::fabs(x)) * (y >= 0.f ? 1.f : -1.f);
    x = fx;
    y = fy;
  }
  const uint32_t ix = std::min(1023u, static_cast<uint32_t>((x * 0.5f + 0.5f) * 1024.f));
  const uint32_t iy = std::min(1023u, static_cast<uint32_t>((y * 0.5f + 0.5f) * 1024.f));
  uint32_t m = 0;
  for (int b = 0; b < 10; ++b) m |= ((ix >> b) & 1u) << (2 * b) | ((iy >> b) & 1u) << (2 * b + 1);
  return m;
}

double stage_seconds(const DdgiReport& report, const std::string& name) {
  for (const auto& [stage, sec] : report.stage_seconds)
    if (stage == name) return sec;
  return 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : GIBAKE_ASSETS_DIR "/reciprocating-saw/ReciprocatingSaw.gltf";
  const unsigned threads = argc > 2 ? static_cast<unsigned>(std::stoul(argv[2])) : 0;
  const uint32_t rays = argc > 3 ? static_cast<uint32_t>(std::stoul(argv[3])) : 256;
  const float sun_lux = argc > 5 ? std::stof(argv[5]) : 1000.f;
  Context ctx;
  ctx.threads = threads;
  Scene scene;
  if (Status st = import_scene(path, ImportOptions{}, ctx, scene); !st) {
    std::fprintf(stderr, "import failed: %s\n", st.message().c_str());
    return 1;
  }
  DdgiSettings s;
  s.rays = rays;
  s.suns.push_back(SunLight{{0.3f, -1.f, 0.2f}, sun_lux, {1, 1, 1}});
  s.sky = {0.2f, 0.3f, 0.5f};
  s.cgal_check = !(argc > 4 && std::string(argv[4]) == "off");
  s.gather = argc > 6 && std::string(argv[6]) == "probes" ? Gather::Probes : Gather::Path;
  if (argc > 7) s.grid.spacing = std::stof(argv[7]);
  // Untimed run that records every ray the bake traces (relocation, probe and shadow rays, with
  // their exact origins, directions and [tnear, tfar]); it also warms caches and the allocator.
  RayCapture captured;
  {
    DdgiSettings cs = s;
    const PipelineDevices platform;
    RunContext capture_run;
    capture_run.platform = &platform;
    capture_run.capture_rays = &captured;
    DdgiResult r;
    DdgiReport rep;
    if (Status st = bake_ddgi(scene, cs, capture_run, ctx, r, rep); !st) {
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
  const double bake_s = seconds_since(t0);
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
  // the probes (grain 2, as the bake) calling rtcIntersect1 / rtcOccluded1 per ray -- once for
  // the relocation rays, once for the probe and shadow rays (the bake traces them in two stages).
  const auto tb = Clock::now();
  std::unique_ptr<PreparedScene> prepared;
  if (!PreparedScene::create(scene, ctx, prepared)) return 1;
  const double build_s = seconds_since(tb);
  auto rtc = static_cast<RTCScene>(prepared->rtc_scene());
  const int32_t probes = result.desc.probe_count();
  tbb::task_arena arena = threads ? tbb::task_arena(static_cast<int>(threads)) : tbb::task_arena();
  std::vector<std::vector<CapturedRay>> relocation(captured.size()), traced(captured.size()),
      primary(captured.size());
  uint64_t shadow_rays = 0;
  for (size_t p = 0; p < captured.size(); ++p)
    for (const CapturedRay& c : captured[p]) {
      (c.kind == CapturedRay::kRelocation ? relocation : traced)[p].push_back(c);
      if (c.kind == CapturedRay::kProbe) primary[p].push_back(c);
      shadow_rays += c.kind == CapturedRay::kShadow;
    }
  auto single = [&](const std::vector<CapturedRay>& l) { return trace_single(rtc, l); };
  const RawRun raw_reloc = run_probes(arena, relocation, single);
  const RawRun raw_trace = run_probes(arena, traced, single);
  const double raw_s = raw_reloc.seconds + raw_trace.seconds;
  const uint64_t raw_rays = raw_reloc.rays + raw_trace.rays;
  const double raw_rate = raw_rays / raw_s;
  const double raw_build_rate = raw_rays / (raw_s + build_s);
  const double bake_rate = report.total_rays() / bake_s;
  std::printf("scene: %s\n", path.c_str());
  std::printf("triangles: %zu, probes: %d (%dx%dx%d), rays/probe: %u, threads: %u\n", scene.triangle_count(), probes,
              result.desc.counts[0], result.desc.counts[1], result.desc.counts[2], rays, threads);
  std::printf("gather: %s\n", s.gather == Gather::Path ? "path" : "probes");
  std::printf("bake: %.3f s wall, %llu rays (%llu primary, %llu bounce, %llu shadow, %llu relocation)\n", bake_s,
              static_cast<unsigned long long>(report.total_rays()), static_cast<unsigned long long>(report.primary_rays),
              static_cast<unsigned long long>(report.bounce_rays),
              static_cast<unsigned long long>(report.shadow_rays),
              static_cast<unsigned long long>(report.relocation_rays));
  for (const auto& [stage, sec] : report.stage_seconds) std::printf("  %-10s %.3f s\n", stage.c_str(), sec);
  std::printf("closed-mesh check: %s (checked %d, inside %u, disagreements %u, inactive outside closed %u)\n",
              s.cgal_check ? "on" : "off", int(report.cgal_checked), report.cgal_inside, report.cgal_disagreements,
              report.cgal_inactive_outside);
  std::printf("probes: %d active, %d inactive, %d relocated; bouncing hits %llu\n", report.active, report.inactive,
              report.relocated, static_cast<unsigned long long>(report.bounce_hits));
  std::printf("(a) raw Embree, captured rays: %llu (%llu occlusion), %llu hit; build %.3f s, trace %.3f s\n",
              static_cast<unsigned long long>(raw_rays), static_cast<unsigned long long>(shadow_rays),
              static_cast<unsigned long long>(raw_reloc.hits + raw_trace.hits), build_s, raw_s);
  std::printf("    relocation rays %llu: %.3f s raw, bake stage 'relocate' %.3f s (%.2fx)\n",
              static_cast<unsigned long long>(raw_reloc.rays), raw_reloc.seconds, stage_seconds(report, "relocate"),
              stage_seconds(report, "relocate") / raw_reloc.seconds);
  std::printf("    probe + shadow rays %llu: %.3f s raw, bake stage 'trace' %.3f s (%.2fx, incl. shading, depth,"
              " pass-0 SH and texels)\n",
              static_cast<unsigned long long>(raw_trace.rays), raw_trace.seconds, stage_seconds(report, "trace"),
              stage_seconds(report, "trace") / raw_trace.seconds);
  std::printf("(a)  trace only        : %.3f Mrays/s\n", raw_rate / 1e6);
  std::printf("(a') build + trace     : %.3f Mrays/s\n", raw_build_rate / 1e6);
  std::printf("(b) bake effective     : %.3f Mrays/s (whole bake_ddgi, BVH build included)\n", bake_rate / 1e6);
  std::printf("(b)/(a)  = %.3f (target >= 0.85)\n", bake_rate / raw_rate);
  std::printf("(b)/(a') = %.3f (both sides include the BVH build); bake wall / raw build+trace = %.3fx\n",
              bake_rate / raw_build_rate, bake_s / (raw_s + build_s));
  std::printf("ceiling on (b)/(a) from the BVH build alone (all other work free, tracing at raw speed): %.3f\n",
              raw_s / (raw_s + build_s));
  if (raw_rays != report.total_rays()) std::printf("WARNING: captured ray count differs from the bake's\n");

  // Would packets or streams trace the probe rays faster? Same rays, each probe's list in the
  // bake's order and sorted by direction (octahedral Morton order).
  auto packets = [&](const std::vector<CapturedRay>& l) { return trace_packets8(rtc, l); };
  auto stream = [&](const std::vector<CapturedRay>& l) { return trace_stream(rtc, l); };
  const RawRun one = run_probes(arena, primary, single);
  const RawRun p8 = run_probes(arena, primary, packets);
  for (auto& l : primary)
    std::stable_sort(l.begin(), l.end(), [](const CapturedRay& x, const CapturedRay& y) {
      return octahedral_morton(x.dir) < octahedral_morton(y.dir);
    });
  const RawRun one_sorted = run_probes(arena, primary, single);
  const RawRun p8_sorted = run_probes(arena, primary, packets);
  const RawRun stream_sorted = run_probes(arena, primary, stream);
  std::printf("probe rays only (%llu), Mrays/s: rtcIntersect1 %.2f, rtcIntersect8 %.2f; sorted by direction: "
              "rtcIntersect1 %.2f, rtcIntersect8 %.2f, rtcIntersect1M coherent %.2f\n",
              static_cast<unsigned long long>(one.rays), one.rays / one.seconds / 1e6, p8.rays / p8.seconds / 1e6,
              one_sorted.rays / one_sorted.seconds / 1e6, p8_sorted.rays / p8_sorted.seconds / 1e6,
              stream_sorted.rays / stream_sorted.seconds / 1e6);
  if (one.hits != p8.hits || one.hits != p8_sorted.hits || one.hits != stream_sorted.hits)
    std::printf("WARNING: packet/stream hit counts differ from single rays\n");
  return 0;
}
