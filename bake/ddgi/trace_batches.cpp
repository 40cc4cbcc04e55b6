#include "bake/ddgi/trace_batches.h"

#include <algorithm>

namespace gibake {

using kernels::HitRecord;
using kernels::RaySample;

namespace {

// Water-filling: the lowest error level L, not below `target`, that `left` rays can bring every
// probe above it down to, a probe's relative error falling as 1/sqrt(rays): a probe of error e
// after n rays needs n ((e / L)^2 - 1) more, at most up to `cap`.
double water_level(const std::vector<double>& error, const std::vector<double>& rays, double target, double cap,
                   double left) {
  auto need = [&](double level) {
    double more = 0.0;
    for (size_t i = 0; i < error.size(); ++i)
      if (error[i] > level) more += std::min(cap - rays[i], rays[i] * ((error[i] / level) * (error[i] / level) - 1.0));
    return more;
  };
  if (need(target) <= left) return target;
  double lo = target, hi = *std::max_element(error.begin(), error.end());
  for (int it = 0; it < 60; ++it) {  // need() falls as the level rises
    const double mid = 0.5 * (lo + hi);
    (need(mid) > left ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace

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
  return st_.ray_budget && !next.empty() ? within_budget(next) : next;
}

std::vector<int32_t> ProbeBatches::within_budget(const std::vector<int32_t>& next) const {
  uint64_t spent = 0;
  for (const RunningStats& r : running_) spent += r.n;
  const uint64_t budget = uint64_t(st_.ray_budget) * running_.size();
  const double left = budget > spent ? double(budget - spent) : 0.0;
  std::vector<double> error(next.size()), rays(next.size());
  for (size_t i = 0; i < next.size(); ++i) {
    error[i] = running_[next[i]].relative_error();
    rays[i] = double(running_[next[i]].n);
  }
  const double target = st_.target_error;
  const double level = water_level(error, rays, target, double(st_.max_rays), left);
  // This batch: the probes above the level (at the target, those not below it), as many as the
  // budget left holds, largest error first (stable: the earlier in `next` among equal errors).
  std::vector<size_t> order;
  for (size_t i = 0; i < next.size(); ++i)
    if (error[i] > level || (level == target && error[i] >= level)) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return error[x] > error[y]; });
  order.resize(std::min(order.size(), size_t(left / double(st_.rays))));
  std::sort(order.begin(), order.end());  // back to `next`'s order
  std::vector<int32_t> kept;
  kept.reserve(order.size());
  for (size_t i : order) kept.push_back(next[i]);
  return kept;
}

}  // namespace gibake
