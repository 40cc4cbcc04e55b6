#include "bake/ddgi/trace_batches.h"

namespace gibake {

using kernels::HitRecord;
using kernels::RaySample;

ProbeBatches::ProbeBatches(const TraceStage& stage, size_t probe_count, ProbeIntegrator& integrator,
                           std::vector<TraceCounters>& counters)
    : st_(stage),
      adaptive_(stage.target_error > 0.f),
      integ_(integrator),
      counters_(counters),
      running_(probe_count),
      hits_(adaptive_ ? probe_count : 0),
      lights_(adaptive_ && stage.probe_lights ? probe_count : 0) {}

HitRecord* ProbeBatches::records(int32_t p, RaySample** lights) {
  if (lights) *lights = nullptr;
  if (!adaptive_) {
    if (lights && st_.probe_lights) {
      std::vector<RaySample>& ls = light_scratch_.local();
      ls.resize(st_.rays);
      *lights = ls.data();
    }
    std::vector<HitRecord>& scratch = scratch_.local();
    scratch.resize(st_.rays);
    return scratch.data();
  }
  const size_t start = hits_[p].size();
  if (lights && st_.probe_lights) {
    lights_[p].resize(start + st_.rays);
    *lights = lights_[p].data() + start;
  }
  hits_[p].resize(start + st_.rays);
  return hits_[p].data() + start;
}

void ProbeBatches::batch_done(int32_t p, const HitRecord* h, const ProbeIntegrals* integrals, const RaySample* lights) {
  for (uint32_t r = 0; r < st_.rays; ++r)
    running_[p].add(ray_stop_value(h[r].radiance0, lights ? lights[r].radiance : nullptr));
  if (!adaptive_) integ_.finish(p, h, st_.rays, counters_[p], running_[p].relative_error(), integrals, lights);
}

void ProbeBatches::finish_tested(int32_t p, const ProbeRayTest& test, const ProbeIntegrals& integrals) {
  integ_.finish(p, test, counters_[p], running_[p].relative_error(), integrals);
}

void ProbeBatches::finish_kept(int32_t p, const ProbeIntegrals* integrals) {
  const RaySample* lights = st_.probe_lights && !integrals ? lights_[p].data() : nullptr;
  integ_.finish(p, hits_[p].data(), hits_[p].size(), counters_[p], running_[p].relative_error(), integrals, lights);
  std::vector<HitRecord>().swap(hits_[p]);
  if (st_.probe_lights) std::vector<RaySample>().swap(lights_[p]);
}

std::vector<int32_t> ProbeBatches::unfinished(const std::vector<int32_t>& pending) const {
  std::vector<int32_t> next;
  if (adaptive_)
    for (int32_t p : pending)
      if (running_[p].n + st_.rays <= st_.max_rays && running_[p].relative_error() >= st_.target_error)
        next.push_back(p);
  return next;
}

}  // namespace gibake
