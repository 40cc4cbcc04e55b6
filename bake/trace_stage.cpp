#include "bake/trace_stage.h"

#include <tbb/enumerable_thread_specific.h>

#include <cmath>
#include <cstdio>

#include "bake/probe_loop.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

using kernels::HitRecord;

float luminance(const float* rgb) { return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]; }

// Welford's running mean and variance of a probe's ray luminances.
struct RunningStats {
  uint64_t n = 0;
  double mean = 0.0, m2 = 0.0;
  void add(double x) {
    ++n;
    const double d = x - mean;
    mean += d / double(n);
    m2 += d * (x - mean);
  }
  double relative_error() const {
    if (n < 2 || mean <= 0.0) return 0.0;
    return std::sqrt(m2 / double(n - 1) / double(n)) / mean;
  }
};

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
  void finish_adaptive(const std::vector<int32_t>& probes);
  double gpu_seconds = 0.0, call_seconds = 0.0, host_seconds = 0.0;

 private:
  struct Scratch {
    std::vector<float> dirs;
    std::vector<HitRecord> hits;
  };
  // Where a probe's records of this batch go: appended to its list (adaptive) or the scratch.
  HitRecord* records(int32_t p, Scratch& sc);
  // After a batch of probe p: its running statistics; without target_error, its integration.
  void batch_done(int32_t p, const HitRecord* h);

  const TraceStage& st_;
  const bool adaptive_;
  ProbeIntegrator& integ_;
  std::vector<TraceCounters>& counters_;
  std::vector<RunningStats> running_;
  std::vector<std::vector<HitRecord>> hits_;  // adaptive batches only
  std::vector<int32_t> slot_;                 // a probe's place in the GPU chunk being traced
  tbb::enumerable_thread_specific<Scratch> scratch_;
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

void Batches::batch_done(int32_t p, const HitRecord* h) {
  for (uint32_t r = 0; r < st_.rays; ++r) running_[p].add(luminance(h[r].radiance0));
  if (!adaptive_) integ_.finish(p, h, st_.rays, counters_[p], running_[p].relative_error());
}

void Batches::trace_cpu(const std::vector<int32_t>& pending, uint32_t batch, const Context& ctx) {
  for_probes_waves(*st_.arena, pending, ctx, "trace", [&](int32_t p) {
    Scratch& sc = scratch_.local();
    sc.dirs.resize(size_t(st_.rays) * 3);
    kernels::generate_probe_rays_from_set(st_.fibonacci, st_.seed, p, batch, st_.rays, sc.dirs.data());
    HitRecord* h = records(p, sc);
    std::vector<CapturedRay>* capture = st_.capture ? &(*st_.capture)[p] : nullptr;
    if (st_.path_gather)
      trace_probe_paths(st_.path, st_.position(p), p, batch, sc.dirs.data(), st_.rays, h, counters_[p], capture);
    else
      trace_probe_rays(st_.path.trace, st_.position(p), p, batch, sc.dirs.data(), st_.rays, h, counters_[p], capture);
    batch_done(p, h);
  });
}

Status Batches::trace_gpu(const std::vector<int32_t>& pending, uint32_t batch, const Context& ctx) {
  PathRays pr;
  pr.rays_per_probe = st_.rays;
  pr.gpu_seconds = &gpu_seconds;
  pr.call_seconds = &call_seconds;
  pr.host_seconds = &host_seconds;
  pr.fill = [&](const std::vector<int32_t>& part, gpu::GpuPathRay* rays) {
    for (size_t i = 0; i < part.size(); ++i) slot_[part[i]] = int32_t(i);
    for_probes(*st_.arena, part, [&](int32_t p) {
      Scratch& sc = scratch_.local();
      sc.dirs.resize(size_t(st_.rays) * 3);
      kernels::generate_probe_rays_from_set(st_.fibonacci, st_.seed, p, batch, st_.rays, sc.dirs.data());
      make_path_rays(st_.position(p), sc.dirs.data(), st_.rays, st_.seed, uint32_t(p), batch,
                     rays + size_t(slot_[p]) * st_.rays);
    });
  };
  size_t traced = 0;
  pr.done = [&](const std::vector<int32_t>& part, const gpu::GpuPathOut* outs) {
    for_probes(*st_.arena, part, [&](int32_t p) {
      HitRecord* h = records(p, scratch_.local());
      const gpu::GpuPathOut* o = outs + size_t(slot_[p]) * st_.rays;
      for (uint32_t r = 0; r < st_.rays; ++r) h[r] = path_record(o[r], counters_[p]);
      batch_done(p, h);
    });
    traced += part.size();
    ctx.report("trace", double(traced), double(pending.size()));
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

void Batches::finish_adaptive(const std::vector<int32_t>& probes) {
  if (!adaptive_) return;
  for_probes(*st_.arena, probes, [&](int32_t p) {
    integ_.finish(p, hits_[p].data(), hits_[p].size(), counters_[p], running_[p].relative_error());
    std::vector<HitRecord>().swap(hits_[p]);
  });
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
  if (st.gpu) {
    char line[192];
    std::snprintf(line, sizeof(line),
                  "vulkan: path kernels %.3f s of device time, %.3f s with ray and result transfers; ray setup and "
                  "integration on the CPU %.3f s",
                  batches.gpu_seconds, batches.call_seconds, batches.host_seconds);
    ctx.note(line);
  }
  batches.finish_adaptive(probes);
  return Status::ok();
}

}  // namespace gibake
