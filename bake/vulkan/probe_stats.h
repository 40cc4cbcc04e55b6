// Per-probe statistics of the path gather on the device (kernels/shaders/probe_stats.comp): the
// path kernel's GpuPathBriefs stay in device memory and are reduced there, batch after batch, into
// one GpuProbeStats per probe of the chunk (counters, misses, saw light, Welford luminance mean and
// m2 in double), so that 48 bytes a probe cross the bus instead of 32 bytes a ray. Needs
// shaderFloat64; without it the path tracer downloads the briefs and the host reduces them.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "bake/ddgi/probe_integrate.h"
#include "bake/trace/probe_rays.h"
#include "io/status.h"
#include "kernels/shaders/gpu_types.h"
#include "kernels/vulkan/context.h"

namespace gibake {

class GpuProbeStatsReducer {
 public:
  // Fails where the device does not expose shaderFloat64.
  static Status create(vk::Context& vk, std::unique_ptr<GpuProbeStatsReducer>& out);
  // Room for a chunk of `probes` probes (grows, never shrinks).
  Status reserve(size_t probes);
  // Reduces the `count` briefs of one batch whose first ray is ray `first` of the chunk, probe
  // after probe; to run after the path kernel that wrote them, before the next batch overwrites them.
  // One dispatch per window of GPU_RAY_WINDOW rays of a probe, to run in order.
  // `lights`: the rays' paired emitter samples (path.comp light_out), whose luminance each ray's
  // value then adds (the combined estimator's terms). `resume`: every probe continues from the
  // state in the buffer (uploaded by the host: its passes before, --target-error) instead of
  // starting fresh at its first ray.
  std::vector<vk::Dispatch> dispatch(const vk::Buffer& briefs, uint32_t first, uint32_t count, uint32_t rays_per_probe,
                                     const vk::Buffer* lights = nullptr, bool resume = false) const;
  // The first `probes` probes' statistics once every batch of the chunk has run.
  Status download(size_t probes, std::vector<gpu::GpuProbeStats>& out);
  // The statistics buffer (the asynchronous route records its download), room for capacity() probes.
  vk::Buffer& buffer() { return stats_; }
  size_t capacity() const { return capacity_; }

 private:
  explicit GpuProbeStatsReducer(vk::Context& vk) : vk_(vk) {}
  vk::Context& vk_;
  vk::Buffer stats_, no_lights_;
  vk::Pipeline pipeline_;
  size_t capacity_ = 0;
};

// A probe's device statistics as the host keeps them: added to `counters` (as count_path adds each
// ray), its ray-test counts, and its luminance statistics (assigned: the state holds every ray of
// the probe, over all its passes with --target-error).
void unpack_probe_stats(const gpu::GpuProbeStats& s, TraceCounters& counters, ProbeRayTest& test,
                        RunningStats& luminance);
// Only the luminance statistics (the stop decision between passes).
RunningStats probe_stats_running(const gpu::GpuProbeStats& s);
// The state of a probe before its first ray (what probe_stats.comp starts from).
gpu::GpuProbeStats fresh_probe_stats();

}  // namespace gibake
