#include "bake/vulkan/probe_stats.h"

#include <cstring>

#include "bake/vulkan/pipelines.h"

namespace gibake {
Status GpuProbeStatsReducer::create(vk::Context& vk, std::unique_ptr<GpuProbeStatsReducer>& out) {
  if (!vk.shader_float64())
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         vk.device().name + " has no shaderFloat64 for the per-probe statistics");
  std::unique_ptr<GpuProbeStatsReducer> r(new GpuProbeStatsReducer(vk));
  GIBAKE_TRY(vk.create_buffer(sizeof(gpu::GpuRaySample), r->no_lights_, "statistics: no emitter samples"));
  GIBAKE_TRY(vk.create_pipeline(pipelines::probe_stats(), r->pipeline_));
  GIBAKE_TRY(r->reserve(1));
  out = std::move(r);
  return Status::ok();
}

Status GpuProbeStatsReducer::reserve(size_t probes) {
  if (probes <= capacity_) return Status::ok();
  GIBAKE_TRY(vk_.create_buffer(probes * sizeof(gpu::GpuProbeStats), stats_, "per-probe statistics"));
  capacity_ = probes;
  return Status::ok();
}

std::vector<vk::Dispatch> GpuProbeStatsReducer::dispatch(const vk::Buffer& briefs, uint32_t first, uint32_t count,
                                                         uint32_t rays_per_probe, const vk::Buffer* lights,
                                                         bool resume) const {
  // The probes this batch touches: from the one holding its first ray to the one holding its last.
  const uint32_t probes = (first + count - 1) / rays_per_probe - first / rays_per_probe + 1;
  // The windows of a probe's rays this batch reaches (all of them once it holds a whole probe).
  const uint32_t from = probes > 1 ? 0 : first % rays_per_probe;
  const uint32_t to = probes > 1 ? rays_per_probe : from + count;
  std::vector<vk::Dispatch> out;
  for (uint32_t w = from / GPU_RAY_WINDOW * GPU_RAY_WINDOW; w < to; w += GPU_RAY_WINDOW) {
    const gpu::ProbeStatsPush push{{first, count, rays_per_probe, (lights ? 1u : 0u) | (resume ? 2u : 0u)},
                                   {w, GPU_RAY_WINDOW, 0u, 0u}};
    vk::Dispatch d;
    d.pipeline = &pipeline_;
    d.buffers = {&briefs, &stats_, lights ? lights : &no_lights_};
    d.push = vk::push_bytes(push);
    d.flat_groups = (probes + GPU_PROBE_STATS_GROUP - 1) / GPU_PROBE_STATS_GROUP;
    out.push_back(std::move(d));
  }
  return out;
}

Status GpuProbeStatsReducer::download(size_t probes, std::vector<gpu::GpuProbeStats>& out) {
  out.resize(probes);
  return vk_.download(stats_, out.data(), probes * sizeof(gpu::GpuProbeStats));
}

void unpack_probe_stats(const gpu::GpuProbeStats& s, TraceCounters& counters, ProbeRayTest& test,
                        RunningStats& luminance) {
  counters.rays += s.counts.x;
  counters.shadow_rays += s.counts.y;
  counters.bounce_rays += s.counts.z;
  counters.back_faces += s.counts.w;
  float nearest;
  std::memcpy(&nearest, &s.test.z, sizeof(nearest));
  // The minimum over the probe's front hits, merged as count_path would have met them.
  if (nearest >= 0.f && (counters.nearest_front < 0.f || nearest < counters.nearest_front))
    counters.nearest_front = nearest;
  test.rays = s.counts.x;
  test.misses = s.test.x;
  test.saw_light = s.test.y != 0;
  luminance = probe_stats_running(s);
}

RunningStats probe_stats_running(const gpu::GpuProbeStats& s) {
  RunningStats r;
  r.n = s.counts.x;
  r.mean = gpu::double_from_words(s.welford.x, s.welford.y);
  r.m2 = gpu::double_from_words(s.welford.z, s.welford.w);
  return r;
}

gpu::GpuProbeStats fresh_probe_stats() {
  gpu::GpuProbeStats s{};
  const float none = -1.f;  // no front hit yet
  std::memcpy(&s.test.z, &none, sizeof(none));
  return s;
}

}  // namespace gibake
