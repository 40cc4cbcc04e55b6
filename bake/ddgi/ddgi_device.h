// The DDGI bake's device contract: every call its stages make that runs per probe or per ray, so the
// stages (relocate_stage, trace_stage, ddgi.cpp, shard_merge) never name a backend. The CPU
// implementation (bake/ddgi/cpu_device.cpp, Embree on the bake's arena) is the reference; the Vulkan
// one (bake/vulkan/ddgi_device.cpp) is its twin and must give the same inputs to the code after it.
// The assembly that runs a bake (bake/pipeline/devices.h) chooses between them and hands the choice
// in through a DdgiPlatform: the DDGI code never picks a backend.
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bake/ddgi/bounce.h"
#include "bake/ddgi/relocate.h"
#include "bake/ddgi/trace_batches.h"
#include "bake/run/arena.h"
#include "bake/run/backend.h"
#include "bake/run/bake_setup.h"
#include "bake/trace/probe_rays.h"
#include "bake/trace/ray_capture.h"
#include "io/context.h"
#include "io/scene.h"

namespace gibake {

// The relocation stage's geometry rays, the same for every pass.
struct RelocationRays {
  const Scene* scene = nullptr;
  TraceSetup setup;  // the bake's; traced with shade = false
  uint64_t seed = 0;
  uint32_t rays = 0;                                       // per probe per pass
  const float* fibonacci = nullptr;                        // the unrotated spherical Fibonacci set of `rays` directions
  float threshold = 0.f;                                   // RelocateParams::threshold
  int passes = 0;                                          // how many passes follow (progress)
  std::function<kernels::float3(int32_t probe)> position;  // rest position + current offset
  RayCapture* capture = nullptr;                           // benchmarks: every ray, per probe
};

// One probe's relocation sums of a pass and the rays traced for them. Called once per probe and
// pass, possibly from several threads at once for different probes.
using RelocationDone = std::function<void(int32_t probe, const RelocationSums& sums, uint64_t traced)>;

class DdgiDevice {
 public:
  virtual ~DdgiDevice() = default;
  // The backend and device the bake runs on (its settings JSON names them).
  virtual const BackendChoice& choice() const = 0;

  // Relocation: readies the rays of every pass, then one pass (pass numbers above any bake batch,
  // kRelocatePassBase + iteration) over `probes`, then end_relocation after the last pass (what
  // the passes needed may then serve the next volume's relocation).
  virtual Status begin_relocation(const RelocationRays& rays) = 0;
  virtual Status relocation_pass(const std::vector<int32_t>& probes, uint32_t pass, const Context& ctx,
                                 const RelocationDone& done) = 0;
  virtual void end_relocation() = 0;

  // The trace stage: readies the probe rays of `stage` (shading data, integration); then batch after
  // batch of `pending` probes, each probe's records (or its statistics and integrals) handed to
  // `batches`; then the probes whose records were kept (--target-error) finished; then end_trace
  // writes the device's notes and releases what tracing needed.
  virtual Status begin_trace(const TraceStage& stage, const Context& ctx) = 0;
  virtual Status trace_batch(ProbeBatches& batches, const std::vector<int32_t>& pending, uint32_t batch,
                             const Context& ctx) = 0;
  virtual Status finish_kept(ProbeBatches& batches, const std::vector<int32_t>& probes) = 0;
  virtual void end_trace(const Context& ctx) = 0;
  // After begin_trace: whether --target-error's batches of `probe_count` probes keep per-ray
  // records on the host until each probe is finished (the CPU always; the device where its passes
  // cannot keep the statistics itself), which the bake's memory estimate must count.
  virtual bool keeps_records_on_host(const TraceStage& stage, size_t probe_count) const = 0;
  // After begin_trace: how many probes (whole blocks of kProbeBlock, by index) run their batches
  // together; trace_probes runs one group's batches to the end before the next group's. Stop
  // decisions read only a probe's block, and rays are keyed by probe and batch, so any grouping
  // gives the same bytes: the device groups as many as its largest buffer holds accumulators for.
  virtual size_t pass_group_probes(const TraceStage& stage, size_t probe_count) const = 0;

  // The probe-feedback bounce passes (--gather probes); `times` gets the stage's seconds.
  virtual Status bounce_passes(const BounceInputs& in, const Context& ctx, std::vector<float>& sh,
                               std::vector<float>& irradiance, BounceTimes& times) = 0;
};

// The reference: Embree in `arena`.
std::unique_ptr<DdgiDevice> make_cpu_ddgi_device(const BackendChoice& choice, tbb::task_arena& arena);

struct GpuSession;
class VulkanWarmup;

// What the DDGI bake and the shard merge ask of the assembly that runs them (bake/pipeline/devices.h):
// the set-up before the first ray, with the backend chosen there, and the device the probes are
// traced on.
class DdgiPlatform {
 public:
  virtual ~DdgiPlatform() = default;
  // The parts the bake lacks (bake/run/bake_setup.h), the Vulkan session of settings.backend among
  // them (taking over `warmup` when given). Call outside any arena; the tasks run in `arena`.
  virtual Status build_setup(const Scene& scene, const SetupSettings& settings, VulkanWarmup* warmup,
                             const BakeSetupParts& parts, const Context& ctx, tbb::task_arena& arena,
                             BakeSetup& out) const = 0;
  // The bake's device: the session's when it holds one, else the CPU in `arena`.
  virtual std::unique_ptr<DdgiDevice> device(GpuSession& session, tbb::task_arena& arena) const = 0;
  // A session of its own for `settings` (the merge's bounce passes) and the choice it was opened for.
  virtual Status open_session(const BackendSettings& settings, std::shared_ptr<GpuSession>& out,
                              BackendChoice& choice) const = 0;
  // The thread that frees what a finished bake on `session` still holds beside the rest of the run;
  // null when the session traced nothing on a device.
  virtual ReleaseBeside* release_thread(GpuSession& session) const = 0;
};

}  // namespace gibake
