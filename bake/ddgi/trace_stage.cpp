#include "bake/ddgi/trace_stage.h"

#include <algorithm>

#include "bake/ddgi/ddgi_device.h"
#include "bake/ddgi/trace_batches.h"

namespace gibake {

Status trace_probes(const TraceStage& stage, DdgiDevice& device, const std::vector<int32_t>& probes, const Context& ctx,
                    ProbeIntegrator& integrator, std::vector<TraceCounters>& counters) {
  TraceStage st = stage;
  st.probe_lights = st.path_gather && ((st.path.emitters && !st.path.emitters->empty()) ||
                                       (st.path.trace.sky && st.path.trace.sky->sampled()));
  GIBAKE_TRY(device.begin_trace(st, ctx));
  ProbeBatches batches(st, counters.size(), integrator, counters);
  std::vector<int32_t> pending = probes;
  for (uint32_t batch = 0; !pending.empty(); ++batch) {
    // A probe goes on only while another batch fits max_rays: a device whose counts did not grow
    // would loop for ever, so say so instead.
    if (uint64_t(batch + 1) * st.rays > std::max(st.max_rays, st.rays))
      return Status::error(ExitCode::RuntimeFailure, "", "trace", "probes past --max-rays: the ray counts did not grow");
    GIBAKE_TRY(device.trace_batch(batches, pending, batch, ctx));
    pending = batches.unfinished(pending);
  }
  if (batches.keeps_hits()) GIBAKE_TRY(device.finish_kept(batches, probes));
  device.end_trace(ctx);
  return Status::ok();
}

}  // namespace gibake
