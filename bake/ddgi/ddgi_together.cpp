#include <algorithm>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/ddgi_bake.h"
#include "bake/ddgi/ddgi_memory.h"
#include "io/results/ddgi_shard.h"
#include "io/timer.h"
#include "kernels/sh.h"

namespace gibake {

namespace {

// The settings a trace stage and its device read: every one but the grid's.
std::string trace_settings(const DdgiSettings& s) {
  nlohmann::json j = nlohmann::json::parse(ddgi_settings_json(s));
  j.erase("grid");
  return j.dump();
}

// Whether `b` may join the stage of `lead`: the same settings but the grid, the same miss depth (the
// device's integration reads the lead's), and neither a shard nor capturing rays.
bool same_trace(DdgiBake& lead, const DdgiVolumeJob& lead_job, DdgiBake& b, const DdgiVolumeJob& job) {
  return !job.run.shard && !job.run.capture_rays && b.max_distance() == lead.max_distance() &&
         trace_settings(*job.settings) == trace_settings(*lead_job.settings);
}

// The host working set while `parts` are traced together: one volume of all their probes, with the
// other volumes' results held beside (each part's held bytes count the rest of the group, which is
// counted here as working set instead).
uint64_t together_need(const std::vector<DdgiBake*>& parts, bool host_records) {
  DdgiMemoryShape all = parts[0]->memory_shape(true, host_records);
  uint64_t in_group = 0;
  for (size_t i = 1; i < parts.size(); ++i) {
    const DdgiMemoryShape one = parts[i]->memory_shape(true, host_records);
    all.probes += one.probes;
    all.left_out += one.left_out;
    all.irradiance_texels += one.irradiance_texels;
    all.depth_texels += one.depth_texels;
    all.fit_points = std::min<uint64_t>(parts[0]->settings().fit.max_samples, all.fit_points + one.fit_points);
    const SurfaceFitSettings& fit = parts[0]->settings().fit;
    all.fit_kept_hits = std::min<uint64_t>(fit.max_samples * fit.paths, all.fit_kept_hits + one.fit_kept_hits);
    const DdgiSettings& s = parts[i]->settings();
    in_group +=
        ddgi_held_bytes(one.probes, kernels::sh_coefficient_count(s.sh_order), s.irradiance_atlas, s.depth_tile);
  }
  all.held_bytes -= std::min(all.held_bytes, in_group);
  return estimate_ddgi_memory(all).total();
}

// The figure recorded as each part's estimate (DdgiReport::memory_estimate) and noted.
Status record_need(const std::vector<DdgiBake*>& parts, uint64_t need, const std::string& route) {
  const std::string text = " (" + std::to_string(parts.size()) + " volumes traced together" + route + ")";
  for (DdgiBake* b : parts) GIBAKE_TRY(b->check_need(need, true, text));
  return Status::ok();
}

// The stage over every part (TraceStage::parts): the lead's settings, each part's probes from the
// next block boundary on, the probes between parts left out.
struct TogetherStage {
  TraceStage stage;
  std::vector<int32_t> probes;
  std::vector<uint8_t> left_out;
};

void make_together_stage(const std::vector<DdgiBake*>& parts, TogetherStage& out) {
  TraceStage& st = out.stage;
  st = parts[0]->trace_stage();
  int32_t first = 0;
  for (size_t i = 0; i < parts.size(); ++i) {
    const DdgiBake& b = *parts[i];
    const uint32_t blocks = probe_blocks(uint32_t(b.probe_count()));
    st.parts.push_back({first, b.trace_stage().counts});
    st.block_part.insert(st.block_part.end(), blocks, uint32_t(i));
    for (int32_t p : b.traced_probes()) out.probes.push_back(first + p);
    out.left_out.resize(size_t(first) + size_t(blocks) * kProbeBlock, 1);
    std::copy(b.left_out().begin(), b.left_out().end(), out.left_out.begin() + first);
    first += int32_t(blocks * kProbeBlock);
  }
  st.counts = {0, 0, 0};
  st.left_out = &out.left_out;
  st.position = [&parts, &st](int32_t p) {
    const TraceStage::Part* part = st.part_of(p);
    return parts[size_t(part - st.parts.data())]->probe_position(p - part->first);
  };
}

// Relocates every part on its own device, the lead's device readied for the stage beside, then
// traces all their probes on the lead's.
Status trace_together(const std::vector<DdgiBake*>& parts, const Context& ctx) {
  TogetherStage together;
  make_together_stage(parts, together);
  DdgiBake& lead = *parts[0];
  lead.begin_trace_setup(&together.stage);
  Status relocated = Status::ok();
  for (DdgiBake* b : parts)
    if (relocated = b->relocate(); !relocated.is_ok()) break;
  if (!relocated.is_ok()) {
    (void)lead.trace_setup_done();  // the set-up reads the stage: waited for before it goes
    return relocated;
  }
  const auto t0 = Clock::now();
  std::vector<TraceCounters> counters(together.left_out.size());
  const auto begun = [&]() -> Status {
    GIBAKE_TRY(lead.trace_setup_done());
    if (!lead.device().keeps_records_on_host(together.stage, counters.size())) return Status::ok();
    return record_need(parts, together_need(parts, true), ", the device keeping the rays' records on the host");
  };
  const auto integrators = [&] {
    std::vector<ProbeIntegrator*> out;
    for (DdgiBake* b : parts) out.push_back(&b->trace_integrator());
    return out;
  };
  GIBAKE_TRY(trace_probes(together.stage, lead.device(), together.probes, ctx, begun, integrators, counters));
  const double seconds = seconds_since(t0);
  for (size_t i = 0; i < parts.size(); ++i) {
    const auto from = counters.begin() + together.stage.parts[i].first;
    parts[i]->traced(std::vector<TraceCounters>(from, from + parts[i]->probe_count()), i == 0 ? seconds : 0.0,
                     "trace (" + std::to_string(parts.size()) + " volumes together)");
  }
  return Status::ok();
}

}  // namespace

Status bake_ddgi_together(const Scene& scene, const std::vector<DdgiVolumeJob>& jobs) {
  const size_t n = jobs.size();
  std::vector<std::unique_ptr<DdgiBake>> bakes;
  std::vector<Clock::time_point> starts(n);
  for (const DdgiVolumeJob& j : jobs) {
    *j.report = DdgiReport{};
    *j.result = DdgiResult{};
    bakes.push_back(std::make_unique<DdgiBake>(scene, *j.settings, j.run, j.ctx, *j.result, *j.report));
  }
  std::vector<uint8_t> started(n, 0);
  const auto start = [&](size_t i) -> Status {
    if (started[i]) return Status::ok();
    started[i] = 1;
    starts[i] = Clock::now();
    GIBAKE_TRY(start_ddgi_bake(*bakes[i], jobs[i].run));
    bakes[i]->fill_trace_stage();
    return Status::ok();
  };
  for (size_t at = 0; at < n;) {
    GIBAKE_TRY(start(at));
    DdgiBake& lead = *bakes[at];
    // The volumes after it that share its trace, while their working set together fits the cap. Only
    // on a device: a pass there costs about the same for a few probes as for thousands, and the CPU
    // has no such floor to share.
    std::vector<DdgiBake*> parts{&lead};
    const bool device = lead.device().choice().backend == Backend::Vulkan && !jobs[at].run.shard &&
                        !jobs[at].run.capture_rays && !jobs[at].settings->backend.vulkan_volumes_apart;
    uint64_t need = 0;
    for (size_t next = at + 1; device && next < n; ++next) {
      GIBAKE_TRY(start(next));
      if (!same_trace(lead, jobs[at], *bakes[next], jobs[next])) break;
      parts.push_back(bakes[next].get());
      const uint64_t with = together_need(parts, false);
      if (with > jobs[at].settings->max_memory_bytes) {
        parts.pop_back();
        break;
      }
      need = with;
    }
    if (parts.size() == 1) {
      lead.begin_trace_setup();
      GIBAKE_TRY(lead.relocate());
      GIBAKE_TRY(lead.trace());
    } else {
      GIBAKE_TRY(record_need(parts, need, ""));
      GIBAKE_TRY(trace_together(parts, jobs[at].ctx));
    }
    // Each bake goes once finished, its working set with it (its result is the caller's).
    for (size_t i = at; i < at + parts.size(); ++i) {
      GIBAKE_TRY(end_ddgi_bake(*bakes[i], *jobs[i].report, starts[i]));
      bakes[i].reset();
    }
    at += parts.size();
  }
  return Status::ok();
}

}  // namespace gibake
