// The DDGI device contract on the CPU (the reference): Embree on the bake's arena.
#include <tbb/enumerable_thread_specific.h>

#include "bake/ddgi/ddgi_device.h"
#include "bake/run/probe_loop.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

using kernels::HitRecord;

class CpuDdgiDevice final : public DdgiDevice {
 public:
  CpuDdgiDevice(const BackendChoice& choice, tbb::task_arena& arena) : choice_(choice), arena_(arena) {}
  const BackendChoice& choice() const override { return choice_; }

  Status begin_relocation(const RelocationRays& rays) override {
    reloc_ = rays;
    reloc_.setup.shade = false;
    return Status::ok();
  }

  Status relocation_pass(const std::vector<int32_t>& probes, uint32_t pass, const Context& ctx,
                         const RelocationDone& done) override {
    struct Scratch {
      std::vector<float> dirs;
      std::vector<HitRecord> hits;
    };
    tbb::enumerable_thread_specific<Scratch> scratch;
    const RelocationRays& r = reloc_;
    for_probes_reporting(arena_, probes, ctx, "relocate", [&](int32_t p) {
      Scratch& sc = scratch.local();
      sc.dirs.resize(size_t(r.rays) * 3);
      sc.hits.resize(r.rays);
      kernels::generate_probe_rays_from_set(r.fibonacci, r.seed, p, pass, r.rays, sc.dirs.data());
      TraceCounters tc;
      trace_probe_rays(r.setup, r.position(p), p, pass, sc.dirs.data(), r.rays, sc.hits.data(), tc,
                       r.capture ? &(*r.capture)[p] : nullptr);
      done(p, relocation_sums(sc.hits.data(), r.rays, r.threshold), tc.rays);
    });
    return Status::ok();
  }

  void end_relocation() override {}

  Status begin_trace(const TraceStage&, const Context&) override { return Status::ok(); }

  Status trace_batch(ProbeBatches& batches, const std::vector<int32_t>& pending, uint32_t batch,
                     const Context& ctx) override {
    const TraceStage& st = batches.stage();
    for_probes_reporting(arena_, pending, ctx, "trace", [&](int32_t p) {
      std::vector<float>& dirs = dirs_.local();
      dirs.resize(size_t(st.rays) * 3);
      const uint32_t key = st.ray_key(p);
      kernels::generate_probe_rays_from_set(st.fibonacci, st.seed, key, batch, st.rays, dirs.data());
      kernels::RaySample* lights = nullptr;  // the probe's emitter samples (probe_lights)
      HitRecord* h = batches.records(p, &lights);
      std::vector<CapturedRay>* capture = st.capture ? &(*st.capture)[p] : nullptr;
      if (st.path_gather)
        trace_probe_paths(st.path, st.position(p), key, batch, dirs.data(), st.rays, h, batches.counters(p), capture,
                          lights);
      else
        trace_probe_rays(st.path.trace, st.position(p), key, batch, dirs.data(), st.rays, h, batches.counters(p),
                         capture);
      batches.batch_done(p, h, nullptr, lights);
    });
    return Status::ok();
  }

  bool keeps_records_on_host(const TraceStage& stage, size_t) const override { return stage.target_error > 0.f; }
  size_t pass_group_probes(const TraceStage&, size_t probe_count) const override { return probe_count; }

  Status finish_kept(ProbeBatches& batches, const std::vector<int32_t>& probes) override {
    for_probes(arena_, probes, [&](int32_t p) { batches.finish_kept(p, nullptr); });
    return Status::ok();
  }

  void end_trace(const Context&) override {}

  Status bounce_passes(const BounceInputs& in, const Context& ctx, std::vector<float>& sh,
                       std::vector<float>& irradiance, BounceTimes& times) override {
    run_bounce_passes(in, arena_, ctx, sh, irradiance, times);
    return Status::ok();
  }

 private:
  BackendChoice choice_;
  tbb::task_arena& arena_;
  RelocationRays reloc_;
  tbb::enumerable_thread_specific<std::vector<float>> dirs_;
};

}  // namespace

std::unique_ptr<DdgiDevice> make_cpu_ddgi_device(const BackendChoice& choice, tbb::task_arena& arena) {
  return std::make_unique<CpuDdgiDevice>(choice, arena);
}

}  // namespace gibake
