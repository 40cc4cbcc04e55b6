// The trace stage: every probe's rays in batches (one batch, or more until --target-error is met),
// each probe finished by the ProbeIntegrator once its last batch is in. The batches run on the bake's
// device (bake/ddgi/ddgi_device.h): Embree on the CPU, or the Vulkan path kernel, which writes the
// same records from the same random keys and can integrate and reduce them on the device.
#pragma once
#include <tbb/task_arena.h>

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "bake/ddgi/probe_integrate.h"
#include "bake/trace/path_gather.h"
#include "bake/trace/probe_rays.h"
#include "bake/trace/ray_capture.h"
#include "io/context.h"
#include "io/scene.h"
#include "kernels/shade.h"

namespace gibake {

class DdgiDevice;

struct TraceStage {
  const Scene* scene = nullptr;
  PathSetup path;                                            // path.trace: the TraceSetup of the probe-feedback gather
  const std::vector<kernels::ShadeLight>* lights = nullptr;  // path.trace.lights as a list (devices upload it)
  bool path_gather = true;
  // The path gather samples the emissive triangles and the sky map from the probe too, MIS-combined
  // with its rays (bake/trace/path_gather.h): set by trace_probes when there is either to sample.
  bool probe_lights = false;
  int sh_order = 2;
  tbb::task_arena* arena = nullptr;
  uint64_t seed = 0;
  uint32_t rays = 0;                 // per probe per batch
  uint32_t max_rays = 0;             // per probe, with target_error
  float target_error = 0.f;          // > 0: more batches until a probe's relative error is below
  // With target_error, > 0: the stage's rays on average per probe, held per block of probes
  // (kProbeBlock): once a block's rays would pass ray_budget x its probes, its batches go to its
  // probes with the largest relative error first.
  uint32_t ray_budget = 0;
  // With target_error, > 0: a probe whose rays so far show it inside geometry (back faces on more
  // than this share, by a margin its ray count makes safe: ProbeBatches::inside) takes no more
  // batches and leaves the budget to the others; its verdict (ProbeIntegrator) is then Inactive.
  float backface_threshold = 0.f;
  // The volume's probe counts (index x + X (y + Y z)): with target_error, a probe's batches are
  // decided on its grid neighbours' variance (ProbeBatches::decision_error); 0: on its own.
  std::array<int32_t, 3> counts{0, 0, 0};
  const float* fibonacci = nullptr;  // the unrotated spherical Fibonacci set of `rays` directions
  std::function<kernels::float3(int32_t probe)> position;
  RayCapture* capture = nullptr;  // benchmarks: every CPU-traced ray, per probe
  // Per probe, 1 when it is not traced at all (DdgiSettings::near_surface_reach): it takes no share
  // of its block's ray budget. Null: every probe of the volume is.
  const std::vector<uint8_t>* left_out = nullptr;

  // A stage over several volumes traced together (bake_ddgi_together in bake/ddgi/ddgi.h): probe p
  // is probe p - first of the part it falls in, a volume of grid `counts`. Each part starts on a
  // block boundary (kProbeBlock) and the probes between parts are left out, so no block spans two
  // volumes and every stop decision is the one its volume makes alone. Empty: one volume, `counts`.
  struct Part {
    int32_t first = 0;
    std::array<int32_t, 3> counts{0, 0, 0};
  };
  std::vector<Part> parts;
  std::vector<uint32_t> block_part;  // with parts: the part of each block of kProbeBlock probes
  const Part* part_of(int32_t p) const;
  // What probe p's rays are keyed on (its index in its own volume): a volume draws the same rays
  // traced with others as alone.
  uint32_t ray_key(int32_t p) const {
    const Part* part = part_of(p);
    return uint32_t(part ? p - part->first : p);
  }
};

// The device's set-up for the trace (DdgiDevice::begin_trace), which a bake may run beside relocation.
Status begin_trace_stage(const TraceStage& stage, DdgiDevice& device, const Context& ctx);

// Traces and finishes every probe in `probes` on `device`; `counters` (one per probe) accumulate the rays.
// `begun` waits for begin_trace_stage (run beside relocation) and returns its status; `integrators`
// is called once, after that (the integrators may be built beside too): one, or with parts one per
// part, which finishes the part's probes by their index in it.
Status trace_probes(const TraceStage& stage, DdgiDevice& device, const std::vector<int32_t>& probes, const Context& ctx,
                    const std::function<Status()>& begun,
                    const std::function<std::vector<ProbeIntegrator*>()>& integrators,
                    std::vector<TraceCounters>& counters);

}  // namespace gibake
