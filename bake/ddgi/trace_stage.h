// The trace stage: every probe's rays in batches (one batch, or more until --target-error is met),
// each probe finished by the ProbeIntegrator once its last batch is in. One CPU/GPU dispatch point:
// a batch is traced by Embree on the bake's arena (trace_probe_paths / trace_probe_rays) or, on the
// Vulkan backend, by the device's path kernel (bake/vulkan/path.h), which writes the same HitRecords
// from the same random keys (the rays themselves made on the device, bake/vulkan/raygen.h). On the
// Vulkan backend the probes' SH, irradiance texels and depth moments are integrated on the device
// too (bake/vulkan/integrate.h), from samples the path kernel leaves there (with --target-error, from
// samples the host builds once every batch is in). The default path gather's per-probe statistics
// are reduced on the device as well (bake/vulkan/probe_stats.h); the states are decided here.
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "bake/ddgi/probe_integrate.h"
#include "bake/trace/path_gather.h"
#include "bake/trace/probe_rays.h"
#include "bake/trace/ray_capture.h"
#include "bake/vulkan/integrate.h"
#include "bake/vulkan/path.h"
#include "io/context.h"

namespace gibake {

struct TraceStage {
  PathSetup path;  // path.trace: the TraceSetup of the probe-feedback gather
  bool path_gather = true;
  GpuPathTracer* gpu = nullptr;        // null: Embree on `arena`
  GpuIntegrator* integrate = nullptr;  // with gpu: integration on the device; null: on the CPU
  tbb::task_arena* arena = nullptr;
  uint64_t seed = 0;
  uint32_t rays = 0;                 // per probe per batch
  uint32_t max_rays = 0;             // per probe, with target_error
  float target_error = 0.f;          // > 0: more batches until a probe's relative error is below
  const float* fibonacci = nullptr;  // the unrotated spherical Fibonacci set of `rays` directions
  std::function<kernels::float3(int32_t probe)> position;
  RayCapture* capture = nullptr;  // benchmarks: every CPU-traced ray, per probe
};

// Traces and finishes every probe in `probes`; `counters` (one per probe) accumulate the rays.
Status trace_probes(const TraceStage& stage, const std::vector<int32_t>& probes, const Context& ctx,
                    ProbeIntegrator& integrator, std::vector<TraceCounters>& counters);

}  // namespace gibake
