// Geometry-only probe rays on the GPU (the relocation pass): the same HitRecords that
// trace_probe_rays writes with TraceSetup::shade = false (distance, miss / front / back face, the
// geometric normal facing the ray), traced by a GpuTracer in chunks of probes.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "bake/trace/probe_rays.h"
#include "bake/trace/ray_capture.h"
#include "bake/vulkan/traverse.h"
#include "io/scene.h"
#include "kernels/shade.h"

namespace gibake {

// What one GPU hit means for a probe ray (trace_probe_rays' rules); counts back faces and the
// nearest front hit in `counters`.
kernels::HitRecord geometry_record(const Scene& scene, const kernels::float3& dir, const gpu::GpuHit& hit,
                                   TraceCounters& counters);

struct GeometryRays {
  uint32_t rays_per_probe = 0;
  std::function<kernels::float3(int32_t probe)> origin;
  std::function<void(int32_t probe, float* dirs)> directions;  // rays_per_probe xyz triples
  // Called with each probe's records once its chunk is traced (from one thread, probe order).
  std::function<void(int32_t probe, const kernels::HitRecord* records, const TraceCounters& counters)> done;
  RayCapture* capture = nullptr;  // benchmarks: every ray, as the CPU pass records them
};

// Traces rays_per_probe rays from each probe in `probes`, at most ~`chunk_rays` rays at a time.
Status trace_geometry_gpu(GpuTracer& tracer, const Scene& scene, const std::vector<int32_t>& probes,
                          const GeometryRays& g, uint64_t chunk_rays = uint64_t(1) << 22);

}  // namespace gibake
