#include "bake/ddgi/trace_batches.h"

#include <algorithm>

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
  if (st_.ray_budget == 0 || next.empty()) return next;
  uint64_t spent = 0;
  for (const RunningStats& r : running_) spent += r.n;
  const uint64_t budget = uint64_t(st_.ray_budget) * running_.size();
  const double left = budget > spent ? double(budget - spent) : 0.0;
  std::vector<double> error(next.size());
  for (size_t i = 0; i < next.size(); ++i) error[i] = running_[next[i]].relative_error();
  // Water-filling: the lowest error level L (not below the target) that the budget left can bring
  // every probe above it down to, a probe's error falling as 1/sqrt(rays): it needs
  // n ((e / L)^2 - 1) more rays, at most up to max_rays. Only probes above L go on.
  auto need = [&](double level) {
    double rays = 0.0;
    for (size_t i = 0; i < next.size(); ++i)
      if (error[i] > level) {
        const double n = double(running_[next[i]].n);
        rays += std::min(double(st_.max_rays) - n, n * ((error[i] / level) * (error[i] / level) - 1.0));
      }
    return rays;
  };
  double level = st_.target_error;
  if (need(level) > left) {
    double lo = level, hi = *std::max_element(error.begin(), error.end());
    for (int it = 0; it < 60; ++it) {  // need() falls as the level rises
      const double mid = 0.5 * (lo + hi);
      (need(mid) > left ? lo : hi) = mid;
    }
    level = hi;
  }
  // This batch: the probes above the level, as many as the budget left holds, largest error first
  // (a stable sort: the earlier probe of `pending` first among equal errors).
  std::vector<size_t> order;
  for (size_t i = 0; i < next.size(); ++i)
    if (error[i] > level || (level == st_.target_error && error[i] >= level)) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return error[x] > error[y]; });
  order.resize(std::min(order.size(), size_t(left / double(st_.rays))));
  std::vector<char> chosen(next.size(), 0);
  for (size_t i : order) chosen[i] = 1;
  std::vector<int32_t> kept;
  kept.reserve(order.size());
  for (size_t i = 0; i < next.size(); ++i)
    if (chosen[i]) kept.push_back(next[i]);
  return kept;
}

}  // namespace gibake
