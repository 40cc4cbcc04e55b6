// The relocation stage: `iterations` passes of geometry-only rays from every probe, each pass
// moving probes away from nearby front faces (bake/ddgi/relocate.h). One CPU/GPU dispatch point: the
// rays go to Embree on the bake's arena, or to the Vulkan device when the bake has one, which
// reduces them to the same RelocationSums there (bake/vulkan/relocate.h; with ray capture, the
// per-ray route of bake/vulkan/geometry.h), so apply_relocation sees the same input either way.
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "bake/ddgi/relocate.h"
#include "bake/trace/probe_rays.h"
#include "bake/trace/ray_capture.h"
#include "bake/vulkan/traverse.h"
#include "io/context.h"
#include "io/scene.h"

namespace gibake {

// Relocation batches use pass numbers above any bake batch, so their rays never repeat a bake ray.
constexpr uint32_t kRelocatePassBase = 0x40000000u;

struct RelocationStage {
  const Scene* scene = nullptr;
  TraceSetup setup;          // the bake's; traced with shade = false
  GpuTracer* gpu = nullptr;  // null: Embree on `arena`
  tbb::task_arena* arena = nullptr;
  uint64_t seed = 0;
  uint32_t rays = 0;  // per probe per pass
  int iterations = 0;
  const float* fibonacci = nullptr;  // the unrotated spherical Fibonacci set of `rays` directions
  RelocateParams params;
  std::function<kernels::float3(int32_t probe)> position;  // rest position + current offset
  RayCapture* capture = nullptr;                           // benchmarks: every ray, per probe
};

// Runs every pass over `probes`. Per probe: `offsets` (xyz, updated), `moved` (set to 1 when it
// moved) and `rays` (incremented by the rays traced). Deterministic for any thread count.
Status relocate_probes(const RelocationStage& stage, const std::vector<int32_t>& probes, const Context& ctx,
                       std::vector<float>& offsets, std::vector<uint8_t>& moved, std::vector<uint64_t>& rays);

}  // namespace gibake
