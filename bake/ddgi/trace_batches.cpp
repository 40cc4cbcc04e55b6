#include "bake/ddgi/trace_batches.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "io/results/ddgi_shard.h"

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

ProbeBatches::ProbeBatches(const TraceStage& stage, size_t probe_count, std::vector<ProbeIntegrator*> integrators,
                           std::vector<TraceCounters>& counters)
    : st_(stage),
      adaptive_(stage.target_error > 0.f),
      integ_(std::move(integrators)),
      counters_(counters),
      running_(probe_count),
      back_faces_(probe_count, 0),
      hits_(adaptive_ ? probe_count : 0),
      lights_(adaptive_ && stage.probe_lights ? probe_count : 0) {}

ProbeIntegrator& ProbeBatches::integrator_of(int32_t p, int32_t& local) const {
  const TraceStage::Part* part = st_.part_of(p);
  local = part ? p - part->first : p;
  return *integ_[part ? size_t(part - st_.parts.data()) : 0];
}

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
  back_faces_[p] = counters_[p].back_faces;
  if (adaptive_) return;
  int32_t local = 0;
  integrator_of(p, local).finish(local, h, st_.rays, counters_[p], running_[p].relative_error(), integrals, lights);
}

void ProbeBatches::finish_tested(int32_t p, const ProbeRayTest& test, const ProbeIntegrals& integrals) {
  // Adaptive: after the last batch, as finish_kept (the device's passes finish here).
  int32_t local = 0;
  integrator_of(p, local).finish(local, test, counters_[p],
                                 adaptive_ ? decision_error(p) : running_[p].relative_error(), integrals);
}

void ProbeBatches::finish_kept(int32_t p, const ProbeIntegrals* integrals) {
  const RaySample* lights = st_.probe_lights && !integrals ? lights_[p].data() : nullptr;
  // The error the batches were decided on, the better estimate of the two (decision_error); every
  // probe's statistics are final here, so it is the same for any thread count.
  int32_t local = 0;
  integrator_of(p, local).finish(local, hits_[p].data(), hits_[p].size(), counters_[p], decision_error(p), integrals,
                                 lights);
  std::vector<HitRecord>().swap(hits_[p]);
  if (st_.probe_lights) std::vector<RaySample>().swap(lights_[p]);
}

double ProbeBatches::decision_error(int32_t p) const {
  const RunningStats& own = running_[p];
  const TraceStage::Part* part = st_.part_of(p);
  const std::array<int32_t, 3>& c = part ? part->counts : st_.counts;
  if (c[0] <= 0 || c[1] <= 0 || c[2] <= 0 || own.n < 1) return own.relative_error();
  const int32_t local = part ? p - part->first : p;  // the neighbours in its own volume's grid
  const int32_t at[3] = {local % c[0], (local / c[0]) % c[1], local / (c[0] * c[1])};
  const int32_t step[3] = {1, c[0], c[0] * c[1]};
  const int64_t block = p / int32_t(kProbeBlock);
  double sum = 0.0;
  int count = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      if (at[axis] + side < 0 || at[axis] + side >= c[axis]) continue;
      const int32_t q = p + side * step[axis];
      const RunningStats& r = running_[size_t(q)];
      if (q / int32_t(kProbeBlock) != block || r.n < 2 || r.mean <= 0.0) continue;  // a shard owns whole blocks
      sum += r.m2 / double(r.n - 1) / (r.mean * r.mean);
      ++count;
    }
  if (count == 0) return own.relative_error();
  return std::sqrt(sum / count / double(own.n));
}

bool ProbeBatches::inside(int32_t p) const {
  const double t = st_.backface_threshold, n = double(running_[p].n);
  if (!(t > 0.0) || n < 1.0) return false;
  return double(back_faces_[p]) / n > t + 3.0 * std::sqrt(t * (1.0 - t) / n);
}

std::vector<int32_t> ProbeBatches::unfinished(const std::vector<int32_t>& pending) const {
  std::vector<int32_t> next;
  if (adaptive_)
    for (int32_t p : pending)
      if (!inside(p) && running_[p].n + st_.rays <= st_.max_rays && decision_error(p) >= st_.target_error)
        next.push_back(p);
  return st_.ray_budget && !next.empty() ? within_budget(next) : next;
}

std::vector<int32_t> ProbeBatches::within_budget(const std::vector<int32_t>& next) const {
  // Each block of `next` decides alone; the kept probes go back in `next`'s order.
  std::map<uint32_t, std::vector<size_t>> blocks;  // block -> positions in `next`
  for (size_t i = 0; i < next.size(); ++i) blocks[uint32_t(next[i]) / kProbeBlock].push_back(i);
  std::vector<uint8_t> keep(next.size(), 0);
  for (const auto& [block, at] : blocks) block_within_budget(block, next, at, keep);
  std::vector<int32_t> kept;
  for (size_t i = 0; i < next.size(); ++i)
    if (keep[i]) kept.push_back(next[i]);
  return kept;
}

void ProbeBatches::block_within_budget(uint32_t block, const std::vector<int32_t>& next, const std::vector<size_t>& at,
                                       std::vector<uint8_t>& keep) const {
  const size_t first = size_t(block) * kProbeBlock;
  const size_t last = std::min(running_.size(), first + kProbeBlock);
  uint64_t spent = 0, sharing = 0;
  for (size_t q = first; q < last; ++q)
    if (!inside(int32_t(q)) && !(st_.left_out && (*st_.left_out)[q])) spent += running_[q].n, ++sharing;
  const uint64_t budget = uint64_t(st_.ray_budget) * sharing;
  const double left = budget > spent ? double(budget - spent) : 0.0;
  std::vector<double> error(at.size()), rays(at.size());
  for (size_t i = 0; i < at.size(); ++i) {
    error[i] = decision_error(next[at[i]]);
    rays[i] = double(running_[next[at[i]]].n);
  }
  const double target = st_.target_error;
  const double level = water_level(error, rays, target, double(st_.max_rays), left);
  // This batch: the probes above the level (at the target, those not below it), as many as the
  // budget left holds, largest error first (stable: the earlier in `next` among equal errors).
  std::vector<size_t> order;
  for (size_t i = 0; i < at.size(); ++i)
    if (error[i] > level || (level == target && error[i] >= level)) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return error[x] > error[y]; });
  order.resize(std::min(order.size(), size_t(left / double(st_.rays))));
  for (size_t i : order) keep[at[i]] = 1;
}

}  // namespace gibake
