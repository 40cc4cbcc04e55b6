// The path gather's chunks in flight on a Vulkan device. Each chunk is one vk::Recording: its probe
// records uploaded, ray generation, the path kernel and the statistics reduction batch after batch,
// the integration of its resident samples and the downloads of what the host needs, in one
// submission. Up to `in_flight` chunks are submitted before the host waits for the oldest, so the
// device runs chunk i+1 while the host reduces chunk i and records chunk i+2. The chunks share the
// device buffers (rays, outputs, samples, tables): one queue runs them in submission order, each
// recording starting with a barrier after the one before; only host staging is per chunk.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "bake/vulkan/integrate.h"
#include "bake/vulkan/path.h"

namespace gibake {

// Where a recorded chunk's results sit in its recording (GpuPathTracer::record and collect).
struct PathRecorded {
  size_t probes = 0;
  uint64_t rays = 0;
  bool brief = false, stats = false;
  bool lights = false;                           // each ray's light sample comes back (PathResult::lights)
  std::vector<uint32_t> batch_rays;              // rays of each batch
  std::vector<size_t> raygen, path, reduce;      // dispatch indices, per batch
  std::vector<size_t> downloads;                 // outputs per batch, or the one statistics download
  std::vector<size_t> light_downloads;           // with `lights`: the light samples per batch
};

// Where a recorded integration's results sit (GpuIntegrator::record_resident, record_accumulate
// and collect). With `paired` (GpuPathTracer::probe_lights), probe i's samples are its counts[i]
// rays followed by their light samples. `downloads` false: the integrals stay on the device
// (record_accumulate).
struct IntegrateRecorded {
  size_t probes = 0;
  uint64_t samples = 0;
  std::vector<gpu::GpuIntegrateProbe> table;
  std::vector<size_t> dispatches;  // one per window of a probe's samples
  size_t sh = 0, irradiance = 0, depth = 0;
  bool downloads = true;
};

struct PipelineOptions {
  uint32_t in_flight = 2;                     // chunks submitted at once (1: the host waits for each)
  uint64_t chunk_rays = uint64_t(1) << 21;    // rays per chunk (whole probes, at least one)
};

// Seconds of a pipelined trace, summed over calls.
struct PipelineTimes {
  double wall = 0.0;    // the calls, end to end
  double device = 0.0;  // each chunk's submission from its first step to its last (timestamps)
  double path = 0.0, raygen = 0.0, stats = 0.0;  // kernels' device time
  double host = 0.0;    // fill and `done` (the host reduction), run while later chunks are in flight
  double record = 0.0;  // recording and submitting
  double wait = 0.0;    // the host waiting for the device
  uint64_t chunks = 0;
  uint32_t in_flight = 0;  // the most chunks in flight at once
};

// A finished chunk: its probes, their outputs (PathResult's rules) and, with an integrator, their
// integrals (probe i of `probes` at slot i). An error ends the trace.
using ChunkDone =
    std::function<Status(const std::vector<int32_t>& probes, const PathResult& out, const GpuIntegrateResult* integrals)>;

// Traces every probe of `probes` (rays_per_probe each, keys of the pass in p.fill's records) in
// chunks of whole probes. With `integrator`, each chunk's samples stay on the device and are
// integrated there in the same submission (with the probe's light samples, each probe's rays are
// followed by them there and integrated paired); with p.resume too (--target-error's passes),
// statistics continue from each probe's state and integrals accumulate in its slot, nothing per ray
// or per texel read back (GpuIntegrator::read_slots after the last pass). `done` is called once per
// chunk, in chunk order, on the calling thread.
Status trace_paths_pipelined(vk::Context& vk, GpuPathTracer& tracer, GpuIntegrator* integrator,
                             const std::vector<int32_t>& probes, const PathRays& p, const ChunkDone& done,
                             const PipelineOptions& options, PipelineTimes& times);

}  // namespace gibake
