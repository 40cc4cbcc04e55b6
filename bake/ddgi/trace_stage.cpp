#include "bake/ddgi/trace_stage.h"

#include <algorithm>
#include <cstdio>

#include "bake/ddgi/ddgi_device.h"
#include "bake/ddgi/trace_batches.h"
#include "io/results/ddgi_shard.h"
#include "io/timer.h"

namespace gibake {

namespace {

// `probes` in groups of whole blocks of kProbeBlock by index, each within `group` indices of its
// block's start (DdgiDevice::pass_group_probes); all of them in one, in their order, when it holds
// every probe.
std::vector<std::vector<int32_t>> pass_groups(const std::vector<int32_t>& probes, size_t group) {
  std::vector<int32_t> sorted = probes;
  if (group < size_t(kProbeBlock)) group = kProbeBlock;
  if (sorted.empty() || group >= size_t(*std::max_element(sorted.begin(), sorted.end())) + 1) return {probes};
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::vector<int32_t>> groups;
  for (size_t at = 0; at < sorted.size();) {
    const int64_t end = int64_t(sorted[at]) / kProbeBlock * kProbeBlock + int64_t(group / kProbeBlock * kProbeBlock);
    size_t next = at;
    while (next < sorted.size() && int64_t(sorted[next]) < end) ++next;
    groups.emplace_back(sorted.begin() + std::ptrdiff_t(at), sorted.begin() + std::ptrdiff_t(next));
    at = next;
  }
  return groups;
}

// The stage as the devices see it: the probe's own light samples when there is anything to sample.
TraceStage with_probe_lights(const TraceStage& stage) {
  TraceStage st = stage;
  st.probe_lights = st.path_gather && ((st.path.emitters && !st.path.emitters->empty()) ||
                                       (st.path.trace.sky && st.path.trace.sky->sampled()));
  return st;
}

}  // namespace

const TraceStage::Part* TraceStage::part_of(int32_t p) const {
  if (parts.empty()) return nullptr;
  return &parts[block_part[size_t(p) / kProbeBlock]];
}

Status begin_trace_stage(const TraceStage& stage, DdgiDevice& device, const Context& ctx) {
  return device.begin_trace(with_probe_lights(stage), ctx);
}

Status trace_probes(const TraceStage& stage, DdgiDevice& device, const std::vector<int32_t>& probes, const Context& ctx,
                    const std::function<Status()>& begun,
                    const std::function<std::vector<ProbeIntegrator*>()>& integrators,
                    std::vector<TraceCounters>& counters) {
  const TraceStage st = with_probe_lights(stage);  // as begin_trace_stage handed it to the device
  const auto t_begin = Clock::now();
  GIBAKE_TRY(begun());
  const auto t_batches = Clock::now();  // the integrator's wait counts here
  ProbeBatches batches(st, counters.size(), integrators(), counters);
  double finishing = 0.0;
  const size_t group_probes = device.pass_group_probes(st, counters.size());
  const std::vector<std::vector<int32_t>> groups = pass_groups(probes, group_probes);
  if (groups.size() > 1) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "trace: adaptive passes in %zu groups of up to %zu probes, one after another (the device holds "
                  "that many probes' accumulators)",
                  groups.size(), group_probes);
    ctx.note(line);
  }
  for (const std::vector<int32_t>& group : groups) {
    std::vector<int32_t> pending = group;
    for (uint32_t batch = 0; !pending.empty(); ++batch) {
      // A probe goes on only while another batch fits max_rays: a device whose counts did not grow
      // would loop for ever, so say so instead.
      if (uint64_t(batch + 1) * st.rays > std::max(st.max_rays, st.rays))
        return Status::error(ExitCode::RuntimeFailure, "", "trace",
                             "probes past --max-rays: the ray counts did not grow");
      GIBAKE_TRY(device.trace_batch(batches, pending, batch, ctx));
      pending = batches.unfinished(pending);
    }
    const auto t_group = Clock::now();
    if (batches.keeps_hits()) GIBAKE_TRY(device.finish_kept(batches, group));
    finishing += seconds_since(t_group);
  }
  const auto t_end = Clock::now();
  device.end_trace(ctx);
  // Where the stage's wall time went on the host's side around a GPU (the devices add their own);
  // a CPU bake has no set-up to wait for and nothing to release, so it says nothing.
  if (device.choice().backend != Backend::Vulkan) return Status::ok();
  char line[256];
  std::snprintf(line, sizeof line,
                "trace stage: waited for the device set-up %.3f s, batches %.3f s, kept probes finished %.3f s, device "
                "released %.3f s",
                seconds_between(t_begin, t_batches), seconds_between(t_batches, t_end) - finishing, finishing,
                seconds_since(t_end));
  ctx.note(line);
  return Status::ok();
}

}  // namespace gibake
