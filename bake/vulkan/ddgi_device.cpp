#include "bake/vulkan/ddgi_device.h"

#include <algorithm>
#include <cstdio>

#include "bake/run/probe_loop.h"
#include "bake/vulkan/bounce.h"
#include "bake/vulkan/geometry.h"
#include "bake/vulkan/integrate.h"
#include "bake/vulkan/path.h"
#include "bake/vulkan/path_pipeline.h"
#include "bake/vulkan/probe_stats.h"
#include "bake/vulkan/raygen.h"
#include "bake/vulkan/relocate.h"
#include "io/results/ddgi_shard.h"
#include "io/timer.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

using kernels::HitRecord;

class VulkanDdgiDevice final : public DdgiDevice {
 public:
  VulkanDdgiDevice(GpuSession& session, tbb::task_arena& arena) : session_(session), arena_(arena) {}
  const BackendChoice& choice() const override { return session_.choice; }

  Status begin_relocation(const RelocationRays& rays) override;
  Status relocation_pass(const std::vector<int32_t>& probes, uint32_t pass, const Context& ctx,
                         const RelocationDone& done) override;
  void end_relocation() override;
  Status begin_trace(const TraceStage& stage, const Context& ctx) override;
  Status trace_batch(ProbeBatches& batches, const std::vector<int32_t>& pending, uint32_t batch,
                     const Context& ctx) override;
  Status finish_kept(ProbeBatches& batches, const std::vector<int32_t>& probes) override;
  void end_trace(const Context& ctx) override;
  bool keeps_records_on_host(const TraceStage& stage, size_t probe_count) const override {
    return stage.target_error > 0.f &&
           !(stage.path_gather && path_->device_stats() && passes_fit(pass_group_probes(stage, probe_count)));
  }
  size_t pass_group_probes(const TraceStage& stage, size_t probe_count) const override {
    if (!(stage.target_error > 0.f && stage.path_gather && path_->device_stats())) return probe_count;
    size_t fit = session_.pass_group_probes;
    if (fit == 0) fit = size_t(session_.vk->max_buffer_bytes() / integrate_->accumulator_bytes(1));
    fit = std::max<size_t>(kProbeBlock, fit / kProbeBlock * kProbeBlock);  // whole blocks
    return std::min(fit, probe_count);
  }
  Status bounce_passes(const BounceInputs& in, const Context& ctx, std::vector<float>& sh,
                       std::vector<float>& irradiance, BounceTimes& times) override;

 private:
  // The device integrates `part` (probe part[i] has count(p) samples, written by fill(p, out)) into
  // integrals_, probe part[i] at slot i.
  using SampleFill = std::function<void(int32_t p, kernels::RaySample* out)>;
  // `paired`: each probe's count(p) rays are followed by their emitter samples (2 count(p) samples).
  Status integrate_samples(const std::vector<int32_t>& part, const std::function<size_t(int32_t)>& count,
                           const SampleFill& fill, bool paired);
  ProbeIntegrals integrals_at(const GpuIntegrateResult& integrals, size_t slot) const;
  // A chunk's probe p from its per-ray outputs (as records), with its integrals when computed.
  void records_done(ProbeBatches& batches, int32_t p, const PathResult& out, const GpuIntegrateResult* integrals);
  // --target-error with the device's statistics: passes continue each probe's statistics and
  // accumulate its integrals on the device; only 48 bytes a probe come back per pass (the stop
  // decision) and, after the last, the integrals (finish_passes).
  // The device passes' accumulators and outputs of `probe_count` slots fit one buffer.
  bool passes_fit(size_t probe_count) const {
    return integrate_->accumulator_bytes(probe_count) <= session_.vk->max_buffer_bytes();
  }
  bool device_passes(const ProbeBatches& batches) const {
    return batches.keeps_hits() && batches.stage().path_gather && path_->device_stats() && passes_fit_;
  }
  Status finish_passes(ProbeBatches& batches, const std::vector<int32_t>& probes);
  // --target-error off the device passes: each pass's per-ray records come back to the host, which
  // keeps them between passes and decides there. Said, with the reason, never silent.
  void note_host_passes(const ProbeBatches& batches, const Context& ctx) const;
  // A group's first batch (trace_probes): its accumulators' slots count from its first probe, and
  // whether the device passes serve it is decided for the whole group.
  void start_group(ProbeBatches& batches, const std::vector<int32_t>& pending, const Context& ctx);
  // A chunk's probes back from the device: their statistics kept for the next pass (`passes`), or
  // each probe finished from its statistics or its records.
  void chunk_done(ProbeBatches& batches, bool passes, const std::vector<int32_t>& part, const PathResult& out,
                  const GpuIntegrateResult* integrals);

  GpuSession& session_;
  tbb::task_arena& arena_;
  // Relocation: the sums kernel, or null for the per-ray route (ray capture, no doubles).
  RelocationRays reloc_;
  std::unique_ptr<GpuRelocation> reloc_sums_;
  int reloc_passes_done_ = 0;
  // Tracing: whole paths (or first hits) and the integration on the device.
  std::unique_ptr<GpuPathTracer> path_;
  std::unique_ptr<GpuIntegrator> integrate_;
  std::vector<int32_t> slot_;                // a probe's place in the chunk being traced
  std::vector<kernels::RaySample> samples_;  // a chunk's integration input, probe by probe
  std::vector<uint64_t> sample_at_;          // where a chunk's probe (by slot) starts in samples_
  GpuIntegrateResult integrals_;  // finish_kept's
  bool passes_fit_ = false;       // the device passes' accumulators fit one buffer
  int32_t pass_base_ = 0;         // the group's first probe: its accumulator slots count from it
  bool host_passes_noted_ = false;
  std::vector<gpu::GpuProbeStats> resume_;  // device passes: each probe's statistics so far
  double finish_seconds_ = 0.0;             // device passes: the integrals read back and finished
  PipelineTimes trace_times_;
};

Status VulkanDdgiDevice::begin_relocation(const RelocationRays& rays) {
  session_.released.wait();
  reloc_ = rays;
  reloc_passes_done_ = 0;
  if (rays.capture) return Status::ok();
  std::unique_ptr<GpuRelocation> earlier = std::move(session_.relocation);
  if (earlier && earlier->serves(*session_.tracer, *rays.scene, rays.fibonacci, rays.rays)) {
    reloc_sums_ = std::move(earlier);
    return Status::ok();
  }
  earlier.reset();
  return GpuRelocation::create(*session_.tracer, *rays.scene, rays.fibonacci, rays.rays, reloc_sums_);
}

void VulkanDdgiDevice::end_relocation() { session_.relocation = std::move(reloc_sums_); }

Status VulkanDdgiDevice::relocation_pass(const std::vector<int32_t>& probes, uint32_t pass, const Context& ctx,
                                         const RelocationDone& done) {
  const RelocationRays& r = reloc_;
  if (reloc_sums_) {  // rays, hits and sums stay on the device; every ray is traced
    std::vector<RelocationSums> sums;
    GIBAKE_TRY(reloc_sums_->sums(probes, r.seed, pass, r.position, r.threshold, sums));
    for (size_t i = 0; i < probes.size(); ++i) done(probes[i], sums[i], r.rays);
  } else {  // the per-ray route: every ray and hit crosses the bus
    GeometryRays g;
    g.rays_per_probe = r.rays;
    g.origin = r.position;
    g.directions = [&](int32_t p, float* dirs) {
      kernels::generate_probe_rays_from_set(r.fibonacci, r.seed, p, pass, r.rays, dirs);
    };
    g.done = [&](int32_t p, const HitRecord* records, const TraceCounters& tc) {
      done(p, relocation_sums(records, r.rays, r.threshold), tc.rays);
    };
    g.capture = r.capture;
    GIBAKE_TRY(trace_geometry_gpu(*session_.tracer, *r.scene, probes, g));
  }
  ctx.report("relocate", double(++reloc_passes_done_), double(r.passes));
  return Status::ok();
}

Status VulkanDdgiDevice::begin_trace(const TraceStage& st, const Context& ctx) {
  GpuPathSetup gs;
  gs.scene = st.scene;
  gs.lod = st.path.trace.lod;
  gs.emitters = st.path.emitters;
  gs.lights = st.lights;
  gs.sky = st.path.trace.sky;
  gs.random_light = st.path.trace.random_light;
  gs.bounces = st.path.bounces;
  gs.roulette_depth = st.path.roulette_depth;
  gs.cone_spread = st.path.trace.cone_spread;
  gs.shadow_bias = st.path.trace.shadow_bias;
  gs.probe_feedback = !st.path_gather;
  gs.probe_lights = st.probe_lights;
  gs.textures = session_.textures.get();
  const auto t0 = Clock::now();
  // An earlier volume's tracer serves this volume when it was made for the same scene, lights and
  // path settings (its shading data and parameters are the bytes create() would make); otherwise it
  // goes, and its memory with it, before another is made.
  std::unique_ptr<GpuPathTracer> earlier = std::move(session_.reference_tracer);
  const bool reused = earlier && earlier->serves(gs);
  if (reused)
    path_ = std::move(earlier);
  else
    session_.released.release(std::move(earlier));
  session_.released.wait();
  if (!reused) {
    Status created;  // in the bake's arena: packing the texel pool runs in parallel, --threads bounds it
    arena_.execute([&] { created = GpuPathTracer::create(*session_.tracer, gs, path_); });
    GIBAKE_TRY(created);
  }
  GIBAKE_TRY(GpuIntegrator::create(*session_.vk, st.sh_order, integrate_));
  trace_times_ = PipelineTimes{};
  host_passes_noted_ = false;
  finish_seconds_ = 0.0;
  resume_.clear();
  const double* setup = path_->setup_seconds();
  char line[256];
  if (reused)
    std::snprintf(line, sizeof(line),
                  "vulkan: path gather setup %.3f s (an earlier volume's shading data and pipelines)",
                  seconds_since(t0));
  else
    std::snprintf(line, sizeof(line),
                  "vulkan: path gather setup %.3f s (shading data packed %.3f s, uploaded %.3f s, pipelines %.3f s)",
                  seconds_since(t0), setup[0], setup[1], setup[2]);
  ctx.note(line);
  return Status::ok();
}

Status VulkanDdgiDevice::integrate_samples(const std::vector<int32_t>& part,
                                           const std::function<size_t(int32_t)>& count, const SampleFill& fill,
                                           bool paired) {
  std::vector<uint32_t> counts(part.size());
  sample_at_.resize(part.size());
  uint64_t total = 0;
  for (size_t i = 0; i < part.size(); ++i) {
    slot_[part[i]] = int32_t(i);
    counts[i] = uint32_t(count(part[i]));
    sample_at_[i] = total;
    total += uint64_t(counts[i]) * (paired ? 2 : 1);
  }
  samples_.resize(total);
  for_probes(arena_, part, [&](int32_t p) { fill(p, samples_.data() + sample_at_[size_t(slot_[p])]); });
  return integrate_->integrate(samples_.data(), counts, integrals_, paired);
}

ProbeIntegrals VulkanDdgiDevice::integrals_at(const GpuIntegrateResult& integrals, size_t slot) const {
  ProbeIntegrals in;
  in.sh = &integrals.sh[slot * size_t(integrate_->sh_values())];
  in.irradiance = &integrals.irradiance[slot * ProbeIntegrator::kIrradianceTile];
  in.depth = &integrals.depth[slot * kDepthTexels * kDepthTexels * 2];
  return in;
}

void VulkanDdgiDevice::records_done(ProbeBatches& batches, int32_t p, const PathResult& out,
                                    const GpuIntegrateResult* integrals) {
  const uint32_t rays = batches.stage().rays;
  kernels::RaySample* lights = nullptr;
  HitRecord* h = batches.records(p, &lights);
  const size_t slot = size_t(slot_[p]);
  if (lights) std::copy_n(&out.lights[slot * rays], rays, lights);
  if (out.briefs.empty())
    for (uint32_t r = 0; r < rays; ++r) h[r] = path_record(out.outs[slot * rays + r], batches.counters(p));
  else
    for (uint32_t r = 0; r < rays; ++r) h[r] = path_record(out.briefs[slot * rays + r], batches.counters(p));
  const ProbeIntegrals in = integrals ? integrals_at(*integrals, slot) : ProbeIntegrals{};
  batches.batch_done(p, h, integrals ? &in : nullptr, lights);
}

void VulkanDdgiDevice::start_group(ProbeBatches& batches, const std::vector<int32_t>& pending, const Context& ctx) {
  // Every buffer of the route must fit one allocation.
  const auto [lo, hi] = std::minmax_element(pending.begin(), pending.end());
  pass_base_ = pending.empty() ? 0 : *lo;
  passes_fit_ = passes_fit(pending.empty() ? 0 : size_t(*hi - *lo) + 1);
  if (device_passes(batches)) {
    if (resume_.size() != batches.probe_count()) resume_.assign(batches.probe_count(), fresh_probe_stats());
    for (int32_t p : pending) resume_[size_t(p)] = fresh_probe_stats();
  } else if (batches.keeps_hits() && !host_passes_noted_) {
    note_host_passes(batches, ctx);
    host_passes_noted_ = true;
  }
}

void VulkanDdgiDevice::chunk_done(ProbeBatches& batches, bool passes, const std::vector<int32_t>& part,
                                  const PathResult& out, const GpuIntegrateResult* integrals) {
  if (passes) {
    // The statistics over every pass so far: kept for the next pass, and the stop decision's.
    for (int32_t p : part) {
      const gpu::GpuProbeStats& s = out.stats[size_t(slot_[p])];
      resume_[size_t(p)] = s;
      batches.running(p) = probe_stats_running(s);
      batches.back_faces(p) = s.counts.w;
    }
  } else if (!out.stats.empty()) {
    // One batch per probe, integrated on the device: the running statistics are fresh.
    for_probes(arena_, part, [&](int32_t p) {
      const size_t slot = size_t(slot_[p]);
      ProbeRayTest test;
      unpack_probe_stats(out.stats[slot], batches.counters(p), test, batches.running(p));
      batches.finish_tested(p, test, integrals_at(*integrals, slot));
    });
  } else {
    for_probes(arena_, part, [&](int32_t p) { records_done(batches, p, out, integrals); });
  }
}

// How the pipeline cuts `total_rays` into chunks (the GpuSession's own settings, when given, win).
PipelineOptions chunk_options(const GpuSession& session, uint32_t max_batch_rays, uint64_t total_rays) {
  PipelineOptions po;
  if (session.in_flight) po.in_flight = session.in_flight;
  // Chunks of two full batches at least: a batch never spans chunks, so smaller chunks would cap the
  // batch size (bake/vulkan/path.h path_batch_rays).
  po.chunk_rays = std::max<uint64_t>(po.chunk_rays, 2 * uint64_t(max_batch_rays));
  // ... but a smaller trace in kMinChunks chunks at least (of kMinChunkRays rays at least): the
  // device starts on the first while the host records the next, and the host's reduction of the
  // last chunk, which nothing hides, stays short (with two chunks the device sits idle for much of the
  // pipeline, docs/BENCHMARKS.md). Chunks hold whole probes; the bytes are the same.
  constexpr uint64_t kMinChunks = 8, kMinChunkRays = uint64_t(1) << 20;
  po.chunk_rays = std::min(po.chunk_rays, std::max(kMinChunkRays, total_rays / kMinChunks));
  if (session.chunk_rays) po.chunk_rays = session.chunk_rays;
  return po;
}

Status VulkanDdgiDevice::trace_batch(ProbeBatches& batches, const std::vector<int32_t>& pending, uint32_t batch,
                                     const Context& ctx) {
  const TraceStage& st = batches.stage();
  slot_.resize(batches.probe_count(), 0);
  if (batch == 0) start_group(batches, pending, ctx);
  const bool passes = device_passes(batches);
  // Without target_error every probe is complete after this batch: the path kernel writes the
  // chunk's integration samples into the integrator's device buffer, which integrates them there.
  // With it, on the device passes, the same samples accumulate into each probe's integrals.
  const bool integrate = !batches.keeps_hits() || passes;
  PathRays pr;
  pr.rays_per_probe = st.rays;
  pr.fibonacci = st.fibonacci;
  pr.seed = st.seed;
  pr.max_distance = batches.integrator().max_distance();
  // The path gather's host work reads only radiance, t, kind and counters when the samples stay on
  // the device; the probe-feedback gather's bounce passes need whole hits.
  pr.brief = integrate && st.path_gather;
  // ... and those reduce to per-probe statistics on the device where it has doubles.
  pr.stats = pr.brief;
  if (passes) {
    pr.resume = &resume_;
    pr.slot_base = pass_base_;
  }
  // A probe's slot is its place in its chunk; chunks in flight hold different probes.
  pr.fill = [&](const std::vector<int32_t>& part, gpu::GpuRayGenProbe* out) {
    for (size_t i = 0; i < part.size(); ++i) {
      slot_[part[i]] = int32_t(i);
      out[i] = raygen_probe(st.position(part[i]), st.seed, st.ray_key(part[i]), batch);
    }
  };
  size_t traced = 0;
  const ChunkDone done = [&](const std::vector<int32_t>& part, const PathResult& out,
                             const GpuIntegrateResult* integrals) -> Status {
    chunk_done(batches, passes, part, out, integrals);
    traced += part.size();
    ctx.report("trace", double(traced), double(pending.size()));
    return Status::ok();
  };
  const PipelineOptions po = chunk_options(session_, path_->max_batch_rays(), uint64_t(pending.size()) * st.rays);
  return trace_paths_pipelined(*session_.vk, *path_, integrate ? integrate_.get() : nullptr, pending, pr, done, po,
                               trace_times_);
}

Status VulkanDdgiDevice::finish_passes(ProbeBatches& batches, const std::vector<int32_t>& probes) {
  // Every probe is finished: its integrals sit in its slot. Read back in runs of slots (bounded
  // host memory), each probe finished from them and its statistics over every pass.
  const auto t0 = Clock::now();
  constexpr size_t kRun = 8192;
  std::vector<int32_t> sorted = probes;
  std::sort(sorted.begin(), sorted.end());
  for (size_t first = 0; first < sorted.size();) {
    const size_t lo = size_t(sorted[first]);
    size_t last = first;
    while (last < sorted.size() && size_t(sorted[last]) < lo + kRun) ++last;
    const size_t count = size_t(sorted[last - 1]) - lo + 1;
    GIBAKE_TRY(integrate_->read_slots(lo - size_t(pass_base_), count, integrals_));
    const std::vector<int32_t> part(sorted.begin() + first, sorted.begin() + last);
    for_probes(arena_, part, [&](int32_t p) {
      ProbeRayTest test;
      unpack_probe_stats(resume_[size_t(p)], batches.counters(p), test, batches.running(p));
      batches.finish_tested(p, test, integrals_at(integrals_, size_t(p) - lo));
    });
    first = last;
  }
  finish_seconds_ += seconds_since(t0);
  return Status::ok();
}

void VulkanDdgiDevice::note_host_passes(const ProbeBatches& batches, const Context& ctx) const {
  std::string why;
  if (!batches.stage().path_gather)
    why = "--gather probes keeps each ray's hit for the bounce passes";
  else if (!path_->device_stats())
    why = "the device has no 64-bit floats (shaderFloat64) for the statistics";
  else
    why = "the pass accumulators (" + std::to_string(integrate_->accumulator_bytes(batches.probe_count()) >> 20) +
          " MiB) exceed the device's largest buffer (" + std::to_string(session_.vk->max_buffer_bytes() >> 20) +
          " MiB)";
  ctx.note(
      "vulkan: adaptive rays with per-ray records on the host between passes (kernels still trace and "
      "integrate on the device): " +
      why);
}

Status VulkanDdgiDevice::finish_kept(ProbeBatches& batches, const std::vector<int32_t>& probes) {
  if (device_passes(batches)) return finish_passes(batches, probes);
  // On the device, in chunks of about as many rays as a trace chunk (bounded host and device memory).
  constexpr uint64_t kChunkRays = uint64_t(1) << 21;
  slot_.resize(batches.probe_count(), 0);
  const float max_distance = batches.integrator().max_distance();
  for (size_t first = 0; first < probes.size();) {
    std::vector<int32_t> part;
    uint64_t rays = 0;
    while (first < probes.size() && (part.empty() || rays + batches.kept(probes[first]).size() <= kChunkRays)) {
      rays += batches.kept(probes[first]).size();
      part.push_back(probes[first++]);
    }
    GIBAKE_TRY(integrate_samples(
        part, [&](int32_t p) { return batches.kept(p).size(); },
        [&](int32_t p, kernels::RaySample* s) {
          const std::vector<HitRecord>& h = batches.kept(p);
          for (size_t r = 0; r < h.size(); ++r)
            s[r] = ProbeIntegrator::integration_sample(h[r].dir_t, h[r].kind(), h[r].radiance0, max_distance);
          if (batches.probe_lights()) std::copy(batches.kept_lights(p).begin(), batches.kept_lights(p).end(), s + h.size());
        },
        batches.probe_lights()));
    for_probes(arena_, part, [&](int32_t p) {
      const ProbeIntegrals in = integrals_at(integrals_, size_t(slot_[p]));
      batches.finish_kept(p, &in);
    });
  }
  return Status::ok();
}

void VulkanDdgiDevice::end_trace(const Context& ctx) {
  // Device time (timestamps) beside wall time: the chunks overlap host work, so the device's busy
  // share of the trace is what the pipeline bought.
  const PipelineTimes& t = trace_times_;
  char line[640];
  std::snprintf(line, sizeof(line),
                "vulkan: trace pipeline %.3f s wall, %llu chunk(s), up to %u in flight; device busy %.3f s "
                "(%.0f%% of the wall time; path and statistics kernels %.3f s, ray generation %.3f s); host "
                "reduction and ray-generation records %.3f s and recording %.3f s beside the device; host waited "
                "%.3f s for it",
                t.wall, static_cast<unsigned long long>(t.chunks), t.in_flight, t.device,
                t.wall > 0.0 ? 100.0 * t.device / t.wall : 0.0, t.path + t.stats, t.raygen, t.host, t.record, t.wait);
  ctx.note(line);
  if (!resume_.empty()) {  // --target-error's passes ran on the device
    std::snprintf(line, sizeof(line),
                  "vulkan: adaptive rays on the device (statistics and integrals kept there between passes); "
                  "integrals read back and probes finished %.3f s after the last pass",
                  finish_seconds_);
    ctx.note(line);
  }
  if (integrate_ && integrate_->kernel_seconds() > 0.0) {
    std::snprintf(line, sizeof(line), "vulkan: integration kernel %.3f s of device time, %.2f GB/s",
                  integrate_->kernel_seconds(), integrate_->kernel_bytes() / integrate_->kernel_seconds() / 1e9);
    ctx.note(line);
  }
  // The integration goes (the bounce passes need none), and the relocation's kernels with it: every
  // volume traced here was relocated before. The path tracer stays with the GpuSession for the
  // reconstruction check's reference paths, and goes with it.
  std::unique_ptr<GpuPathTracer::Batches> batches;
  path_->release_batches(batches);
  session_.reference_tracer = std::move(path_);
  session_.released.release(std::move(integrate_), std::move(batches),
                            std::move(session_.relocation));  // the pipeline waited for the device
  integrals_ = GpuIntegrateResult{};
  std::vector<gpu::GpuProbeStats>().swap(resume_);
}

Status VulkanDdgiDevice::bounce_passes(const BounceInputs& in, const Context& ctx, std::vector<float>& sh,
                                       std::vector<float>& irradiance, BounceTimes& times) {
  if (in.bounces == 0) {  // no passes (the path gather): pass 0's SH, nothing to upload
    run_bounce_passes(in, arena_, ctx, sh, irradiance, times);
    return Status::ok();
  }
  session_.released.wait();
  const auto t0 = Clock::now();
  GpuBounceStats stats;
  // One submission for every pass: progress can only say it started and ended.
  ctx.report("bounces (vulkan)", 0.0, 1.0);
  GIBAKE_TRY(run_bounce_passes_gpu(*session_.vk, in, sh, irradiance, stats));
  ctx.report("bounces (vulkan)", 1.0, 1.0);
  times.stage_seconds.emplace_back("bounces (vulkan)", seconds_since(t0));
  char line[256];
  std::snprintf(line, sizeof(line),
                "vulkan: bounce kernels %.3f s of device time (weights %.3f s, %d passes %.3f s), %u hit chunk(s), "
                "%u submission(s), %.1f MB of device memory",
                stats.weights_seconds + stats.pass_seconds, stats.weights_seconds, in.bounces, stats.pass_seconds,
                stats.chunks, stats.submissions, stats.device_bytes / 1e6);
  ctx.note(line);
  return Status::ok();
}

}  // namespace

std::unique_ptr<DdgiDevice> make_vulkan_ddgi_device(GpuSession& session, tbb::task_arena& arena) {
  return std::make_unique<VulkanDdgiDevice>(session, arena);
}

}  // namespace gibake
