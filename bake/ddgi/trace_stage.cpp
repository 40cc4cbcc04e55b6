#include "bake/ddgi/trace_stage.h"

#include <tbb/enumerable_thread_specific.h>

#include <cstdio>

#include "bake/run/probe_loop.h"
#include "bake/vulkan/probe_stats.h"
#include "bake/vulkan/raygen.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

using kernels::HitRecord;

// What the batches of one stage share.
class Batches {
 public:
  Batches(const TraceStage& st, size_t probe_count, ProbeIntegrator& integ, std::vector<TraceCounters>& counters)
      : st_(st),
        adaptive_(st.target_error > 0.f),
        integ_(integ),
        counters_(counters),
        running_(probe_count),
        hits_(adaptive_ ? probe_count : 0),
        slot_(probe_count, 0) {}

  void trace_cpu(const std::vector<int32_t>& pending, uint32_t batch, const Context& ctx);
  Status trace_gpu(const std::vector<int32_t>& pending, uint32_t batch, const Context& ctx);
  // The probes of `pending` that need another batch (none without target_error).
  std::vector<int32_t> unfinished(const std::vector<int32_t>& pending) const;
  // With target_error: finishes every probe from all its batches' records.
  Status finish_adaptive(const std::vector<int32_t>& probes);
  double gpu_seconds = 0.0, raygen_seconds = 0.0, call_seconds = 0.0, host_seconds = 0.0;

 private:
  struct Scratch {
    std::vector<float> dirs;
    std::vector<HitRecord> hits;
  };
  // Where a probe's records of this batch go: appended to its list (adaptive) or the scratch.
  HitRecord* records(int32_t p, Scratch& sc);
  // After a batch of probe p: its running statistics; without target_error, its integration (from
  // `integrals` when the device computed them).
  void batch_done(int32_t p, const HitRecord* h, const ProbeIntegrals* integrals);
  // A chunk's probe p from its per-ray outputs (as records), or every probe of `part` from its
  // statistics reduced on the device.
  void records_done(int32_t p, const PathResult& out);
  void stats_done(const std::vector<int32_t>& part, const std::vector<gpu::GpuProbeStats>& stats);
  // The device integrates `part` (probe part[i] has count(p) samples, written by fill(p, out)) into
  // integrals_, probe part[i] at slot i.
  using SampleFill = std::function<void(int32_t p, kernels::RaySample* out)>;
  Status integrate_gpu(const std::vector<int32_t>& part, const std::function<size_t(int32_t)>& count,
                       const SampleFill& fill);
  ProbeIntegrals integrals_at(size_t slot) const;

  const TraceStage& st_;
  const bool adaptive_;
  ProbeIntegrator& integ_;
  std::vector<TraceCounters>& counters_;
  std::vector<RunningStats> running_;
  std::vector<std::vector<HitRecord>> hits_;  // adaptive batches only
  std::vector<int32_t> slot_;                 // a probe's place in the GPU chunk being traced
  tbb::enumerable_thread_specific<Scratch> scratch_;
  std::vector<kernels::RaySample> samples_;  // a chunk's integration input, probe by probe
  std::vector<uint64_t> sample_at_;          // where a chunk's probe (by slot) starts in samples_
  GpuIntegrateResult integrals_;
};

HitRecord* Batches::records(int32_t p, Scratch& sc) {
  if (!adaptive_) {
    sc.hits.resize(st_.rays);
    return sc.hits.data();
  }
  const size_t start = hits_[p].size();
  hits_[p].resize(start + st_.rays);
  return hits_[p].data() + start;
}

void Batches::batch_done(int32_t p, const HitRecord* h, const ProbeIntegrals* integrals) {
  for (uint32_t r = 0; r < st_.rays; ++r) running_[p].add(ray_luminance(h[r].radiance0));
  if (!adaptive_) integ_.finish(p, h, st_.rays, counters_[p], running_[p].relative_error(), integrals);
}

Status Batches::integrate_gpu(const std::vector<int32_t>& part, const std::function<size_t(int32_t)>& count,
                              const SampleFill& fill) {
  std::vector<uint32_t> counts(part.size());
  sample_at_.resize(part.size());
  uint64_t total = 0;
  for (size_t i = 0; i < part.size(); ++i) {
    slot_[part[i]] = int32_t(i);
    counts[i] = uint32_t(count(part[i]));
    sample_at_[i] = total;
    total += counts[i];
  }
  samples_.resize(total);
  for_probes(*st_.arena, part, [&](int32_t p) { fill(p, samples_.data() + sample_at_[size_t(slot_[p])]); });
  return st_.integrate->integrate(samples_.data(), counts, integrals_);
}

ProbeIntegrals Batches::integrals_at(size_t slot) const {
  ProbeIntegrals in;
  in.sh = &integrals_.sh[slot * size_t(st_.integrate->sh_values())];
  in.irradiance = &integrals_.irradiance[slot * ProbeIntegrator::kIrradianceTile];
  in.depth = &integrals_.depth[slot * kDepthTexels * kDepthTexels * 2];
  return in;
}

void Batches::trace_cpu(const std::vector<int32_t>& pending, uint32_t batch, const Context& ctx) {
  for_probes_reporting(*st_.arena, pending, ctx, "trace", [&](int32_t p) {
    Scratch& sc = scratch_.local();
    sc.dirs.resize(size_t(st_.rays) * 3);
    kernels::generate_probe_rays_from_set(st_.fibonacci, st_.seed, p, batch, st_.rays, sc.dirs.data());
    HitRecord* h = records(p, sc);
    std::vector<CapturedRay>* capture = st_.capture ? &(*st_.capture)[p] : nullptr;
    if (st_.path_gather)
      trace_probe_paths(st_.path, st_.position(p), p, batch, sc.dirs.data(), st_.rays, h, counters_[p], capture);
    else
      trace_probe_rays(st_.path.trace, st_.position(p), p, batch, sc.dirs.data(), st_.rays, h, counters_[p], capture);
    batch_done(p, h, nullptr);
  });
}

void Batches::records_done(int32_t p, const PathResult& out) {
  HitRecord* h = records(p, scratch_.local());
  const size_t slot = size_t(slot_[p]);
  if (out.briefs.empty())
    for (uint32_t r = 0; r < st_.rays; ++r) h[r] = path_record(out.outs[slot * st_.rays + r], counters_[p]);
  else
    for (uint32_t r = 0; r < st_.rays; ++r) h[r] = path_record(out.briefs[slot * st_.rays + r], counters_[p]);
  const bool integrate = st_.integrate && !adaptive_;
  const ProbeIntegrals in = integrate ? integrals_at(slot) : ProbeIntegrals{};
  batch_done(p, h, integrate ? &in : nullptr);
}

void Batches::stats_done(const std::vector<int32_t>& part, const std::vector<gpu::GpuProbeStats>& stats) {
  // Only without target_error (one batch per probe, integrated on the device): running_ is fresh.
  for_probes(*st_.arena, part, [&](int32_t p) {
    const size_t slot = size_t(slot_[p]);
    ProbeRayTest test;
    unpack_probe_stats(stats[slot], counters_[p], test, running_[p]);
    integ_.finish(p, test, counters_[p], running_[p].relative_error(), integrals_at(slot));
  });
}

Status Batches::trace_gpu(const std::vector<int32_t>& pending, uint32_t batch, const Context& ctx) {
  // Without target_error every probe is complete after this batch: the path kernel writes the
  // chunk's integration samples into the integrator's device buffer, which integrates them there.
  const bool integrate = st_.integrate && !adaptive_;
  PathRays pr;
  pr.rays_per_probe = st_.rays;
  pr.fibonacci = st_.fibonacci;
  pr.seed = st_.seed;
  pr.max_distance = integ_.max_distance();
  // The path gather's host work reads only radiance, t, kind and counters when the samples stay on
  // the device; the probe-feedback gather's bounce passes need whole hits.
  pr.brief = integrate && st_.path_gather;
  // ... and those reduce to per-probe statistics on the device where it has doubles.
  pr.stats = pr.brief;
  pr.gpu_seconds = &gpu_seconds;
  pr.raygen_seconds = &raygen_seconds;
  pr.call_seconds = &call_seconds;
  pr.host_seconds = &host_seconds;
  pr.fill = [&](const std::vector<int32_t>& part, gpu::GpuRayGenProbe* out) {
    for (size_t i = 0; i < part.size(); ++i) {
      slot_[part[i]] = int32_t(i);
      out[i] = raygen_probe(st_.position(part[i]), st_.seed, uint32_t(part[i]), batch);
    }
  };
  if (integrate)
    pr.samples = [&](uint64_t rays, const vk::Buffer*& out) {
      vk::Buffer* buffer = nullptr;
      GIBAKE_TRY(st_.integrate->reserve_samples(rays, buffer));
      out = buffer;
      return Status::ok();
    };
  size_t traced = 0;
  pr.done = [&](const std::vector<int32_t>& part, const PathResult& out) -> Status {
    if (integrate)
      GIBAKE_TRY(st_.integrate->integrate_resident(std::vector<uint32_t>(part.size(), st_.rays), integrals_));
    if (!out.stats.empty()) {
      stats_done(part, out.stats);
    } else {
      for_probes(*st_.arena, part, [&](int32_t p) { records_done(p, out); });
    }
    traced += part.size();
    ctx.report("trace", double(traced), double(pending.size()));
    return Status::ok();
  };
  return trace_paths_gpu(*st_.gpu, pending, pr);
}

std::vector<int32_t> Batches::unfinished(const std::vector<int32_t>& pending) const {
  std::vector<int32_t> next;
  if (adaptive_)
    for (int32_t p : pending)
      if (hits_[p].size() + st_.rays <= st_.max_rays && running_[p].relative_error() >= st_.target_error)
        next.push_back(p);
  return next;
}

Status Batches::finish_adaptive(const std::vector<int32_t>& probes) {
  if (!adaptive_) return Status::ok();
  if (!st_.integrate) {
    for_probes(*st_.arena, probes, [&](int32_t p) {
      integ_.finish(p, hits_[p].data(), hits_[p].size(), counters_[p], running_[p].relative_error());
      std::vector<HitRecord>().swap(hits_[p]);
    });
    return Status::ok();
  }
  // On the device, in chunks of about as many rays as a trace chunk (bounded host and device memory).
  constexpr uint64_t kChunkRays = uint64_t(1) << 21;
  for (size_t first = 0; first < probes.size();) {
    std::vector<int32_t> part;
    uint64_t rays = 0;
    while (first < probes.size() && (part.empty() || rays + hits_[probes[first]].size() <= kChunkRays)) {
      rays += hits_[probes[first]].size();
      part.push_back(probes[first++]);
    }
    GIBAKE_TRY(integrate_gpu(
        part, [&](int32_t p) { return hits_[p].size(); },
        [&](int32_t p, kernels::RaySample* s) {
          const std::vector<HitRecord>& h = hits_[p];
          for (size_t r = 0; r < h.size(); ++r)
            s[r] = ProbeIntegrator::integration_sample(h[r].dir_t, h[r].kind(), h[r].radiance0, integ_.max_distance());
        }));
    for_probes(*st_.arena, part, [&](int32_t p) {
      const ProbeIntegrals in = integrals_at(size_t(slot_[p]));
      integ_.finish(p, hits_[p].data(), hits_[p].size(), counters_[p], running_[p].relative_error(), &in);
      std::vector<HitRecord>().swap(hits_[p]);
    });
  }
  return Status::ok();
}

}  // namespace

Status trace_probes(const TraceStage& st, const std::vector<int32_t>& probes, const Context& ctx,
                    ProbeIntegrator& integrator, std::vector<TraceCounters>& counters) {
  Batches batches(st, counters.size(), integrator, counters);
  std::vector<int32_t> pending = probes;
  for (uint32_t batch = 0; !pending.empty(); ++batch) {
    if (st.gpu)
      GIBAKE_TRY(batches.trace_gpu(pending, batch, ctx));
    else
      batches.trace_cpu(pending, batch, ctx);
    pending = batches.unfinished(pending);
  }
  GIBAKE_TRY(batches.finish_adaptive(probes));
  if (st.gpu) {
    char line[384];
    std::snprintf(line, sizeof(line),
                  "vulkan: path (and per-probe statistics) kernels %.3f s of device time, ray generation kernel "
                  "%.3f s; %.3f s with probe-record and result transfers; probe records, statistics and "
                  "integration transfers on the CPU %.3f s",
                  batches.gpu_seconds, batches.raygen_seconds, batches.call_seconds, batches.host_seconds);
    ctx.note(line);
  }
  if (st.integrate && st.integrate->kernel_seconds() > 0.0) {
    char line[192];
    std::snprintf(line, sizeof(line), "vulkan: integration kernel %.3f s of device time, %.2f GB/s",
                  st.integrate->kernel_seconds(), st.integrate->kernel_bytes() / st.integrate->kernel_seconds() / 1e9);
    ctx.note(line);
  }
  return Status::ok();
}

}  // namespace gibake
