#include "bake/ddgi/volumes.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <utility>

#include "bake/ddgi/ddgi_memory.h"
#include "bake/ddgi/refine.h"
#include "bake/ddgi/shard_bake.h"
#include "bake/ddgi/volume_plan.h"
#include "bake/run/bake_setup.h"
#include "io/size_text.h"
#include "kernels/sh.h"

namespace gibake {

namespace {

Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "probe volumes", what); }

}  // namespace

Status validate_volume_settings(const VolumeSettings& vs) {
  if (!vs.default_volume && vs.given.empty())
    return bad("--default-volume off leaves no probe volume: add at least one --probe-volume");
  for (size_t i = 0; i < vs.given.size(); ++i) {
    const GivenVolume& g = vs.given[i];
    const std::string which = "volume " + std::to_string(i + 1) + ": ";
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(g.lo[a]) || !std::isfinite(g.hi[a]) || !(g.hi[a] > g.lo[a]))
        return bad(which + "the box's max must be above its min on every axis");
    if (!(g.spacing >= 0.f) || !std::isfinite(g.spacing)) return bad(which + "the spacing must be a positive number");
  }
  return Status::ok();
}

std::string volume_settings_json(const VolumeSettings& vs) {
  nlohmann::json given = nlohmann::json::array();
  for (const GivenVolume& g : vs.given) {
    given.push_back({{"min", g.lo}, {"max", g.hi}, {"spacing", g.spacing}});
    if (g.near_surfaces) given.back()["near_surfaces"] = true;  // only when asked: other files keep their bytes
  }
  nlohmann::json j{{"default_volume", vs.default_volume}, {"detail_volumes", vs.detail_volumes}, {"given", given}};
  if (vs.refined_otherwise()) j["refine_budget"] = vs.refine.budget;
  if (vs.check_budget != 0) j["refine_by_check"] = vs.check_budget;
  if (!vs.views.empty()) {  // only when asked: other files keep their bytes
    nlohmann::json views = nlohmann::json::array();
    for (const ViewCamera& v : vs.views) views.push_back(v.name);
    j["near_cameras"] = views;
    if (vs.view_spacing > 0.f) j["near_spacing"] = vs.view_spacing;
  }
  return j.dump();
}

const char* volume_kind_name(VolumeKind kind) {
  switch (kind) {
    case VolumeKind::Detail: return "detail";
    case VolumeKind::Given: return "given";
    case VolumeKind::Refined: return "refined";
    case VolumeKind::View:
      return "view";
    default: return "default";
  }
}

std::string volumes_json(const std::vector<BakedVolume>& volumes) {
  nlohmann::json all = nlohmann::json::array();
  for (size_t i = 0; i < volumes.size(); ++i) {
    const BakedVolume& v = volumes[i];
    const DdgiVolumeDesc& d = v.result.desc;
    all.push_back({{"index", i},
                   {"kind", volume_kind_name(v.kind)},
                   {"why", v.why},
                   {"counts", d.counts},
                   {"spacing", d.spacing},
                   {"grid_min", d.grid_min},
                   {"grid_max", d.grid_max},
                   {"probes", d.probe_count()},
                   {"active", v.report.active}});
    // What its probes were traced with: refined volumes have a ray budget of their own (refine.h).
    const nlohmann::json settings = nlohmann::json::parse(v.result.settings_json, nullptr, false);
    if (settings.is_object() && settings.contains("rays") && settings.contains("ray_budget")) {
      all.back()["rays"] = settings["rays"];
      all.back()["ray_budget"] = settings["ray_budget"];
    }
  }
  return all.dump();
}

std::string volume_line(size_t index, const BakedVolume& v) {
  const DdgiVolumeDesc& d = v.result.desc;
  char text[200];
  std::snprintf(text, sizeof text, "volume %zu (%s): %dx%dx%d = %d probes, spacing %.3g m, %d active; ", index,
                volume_kind_name(v.kind), d.counts[0], d.counts[1], d.counts[2], d.probe_count(),
                double(min_cell_size(d)), v.report.active);
  std::string line = text;
  if (v.report.left_out > 0) {
    std::snprintf(text, sizeof text, "%d left out (no surface within %.3g m); ", v.report.left_out,
                  double(kNearSurfaceSpacings * min_cell_size(d)));
    line += text;
  }
  return line + v.why;
}

namespace {

// What a volume keeps until the file is written (ddgi_held_bytes) for these settings.
uint64_t held_bytes(const DdgiSettings& s, const DdgiVolumeDesc& d) {
  return ddgi_held_bytes(uint64_t(d.probe_count()), kernels::sh_coefficient_count(s.sh_order), s.irradiance_atlas,
                         s.depth_tile);
}

// The volumes bake one after the other, so the bake's working set is the largest volume's estimate
// (each counts the others' held results). The first volume notes its own; when a later one (a
// refined volume, whose lines are quiet) needs more, the user is told that figure too. Volumes
// before `first_unnoted` had their figure told already.
void note_largest_estimate(const DdgiSettings& s, const std::vector<BakedVolume>& out, const Context& ctx,
                           size_t first_unnoted) {
  size_t largest = 0;
  for (size_t i = 1; i < out.size(); ++i)
    if (out[i].report.memory_estimate > out[largest].report.memory_estimate) largest = i;
  if (largest < first_unnoted) return;
  ctx.note("memory: about " + std::to_string(out[largest].report.memory_estimate >> 20) +
           " MiB of host memory estimated for volume " + std::to_string(largest) + " (" +
           volume_kind_name(out[largest].kind) + "), the largest (--max-memory " +
           size_text(double(s.max_memory_bytes)) + ")");
}

// The refinement a bake runs beside its first volume (plan_refinement): on a thread of its own (its
// parallel work in arenas of --threads, as when it runs first), not a BesideTask, whose task in an
// arena no thread has entered waits for a worker the first volume's bake may keep busy; on a copy
// of the plan (the first volume's bake reads the plan's grids); quiet until it is joined, when its
// notes and warnings follow in order.
class RefinementBeside {
 public:
  RefinementBeside(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, const VolumePlan& plan,
                   const PreparedScene* prepared, const Context& ctx)
      : ctx_(ctx), first_new_(plan.volumes.size()) {
    plan_.volumes = plan.volumes;
    Context quiet;
    quiet.threads = ctx.threads;
    quiet.warn = [this](const std::string& m) { keep(true, m); };
    quiet.info = [this](const std::string& m) { keep(false, m); };
    thread_ = std::thread([this, &scene, &s, &vs, prepared, quiet] {
      try {
        status_ = plan_refinement(scene, s, vs, quiet, plan_, prepared);
      } catch (...) {
        error_ = std::current_exception();
      }
    });
  }
  RefinementBeside(const RefinementBeside&) = delete;
  RefinementBeside& operator=(const RefinementBeside&) = delete;
  ~RefinementBeside() {
    if (thread_.joinable()) thread_.join();
  }
  // Joins, tells what it said and appends its volumes and lines to `plan`.
  Status join(VolumePlan& plan) {
    thread_.join();
    for (const auto& [warning, m] : messages_) warning ? ctx_.warning(m) : ctx_.note(m);
    if (error_) std::rethrow_exception(error_);
    GIBAKE_TRY(status_);
    for (size_t i = first_new_; i < plan_.volumes.size(); ++i) plan.volumes.push_back(std::move(plan_.volumes[i]));
    plan.refine_text = plan_.refine_text;
    plan.refine_seconds = plan_.refine_seconds;
    return Status::ok();
  }

 private:
  void keep(bool warning, const std::string& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back({warning, m});
  }

  VolumePlan plan_;  // the volumes planned before it, then its own
  const Context& ctx_;
  const size_t first_new_;
  std::mutex mutex_;
  std::vector<std::pair<bool, std::string>> messages_;  // warning?, text
  Status status_ = Status::ok();
  std::exception_ptr error_;
  std::thread thread_;  // last: started once everything it reads is made
};

// Bakes the planned volumes in order, each on its placed grid; every volume after the first reads
// what the first built (BVH, mips, enclosure voxels, Vulkan device) instead of building it again,
// and those after it are traced together where they can (bake_ddgi_together). `refine_beside`:
// the refinement left out of the plan runs beside the first volume's bake, whose working set
// counts its voxels (`refine_bytes`), and its volumes follow. With a shard, `first_blocks[i]`:
// where volume i's blocks begin among the bake's `total_blocks`.
Status bake_planned(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, VolumePlan& plan,
                    const RunContext& first, const RunContext& run, const Context& ctx, bool refine_beside,
                    uint64_t refine_bytes, const std::vector<uint32_t>& first_blocks, uint32_t total_blocks,
                    std::vector<BakedVolume>& out) {
  std::vector<uint64_t> held;
  uint64_t all_held = 0;
  std::vector<DdgiSettings> settings;
  std::vector<DdgiShardRun> shards;
  std::vector<DdgiVolumeJob> jobs;
  // Every volume's result stays until the write, so each bake's estimate counts those of the others
  // planned by then (a shard hands its probes over instead and holds its range only).
  const auto size_for_plan = [&] {
    const size_t count = plan.volumes.size();
    out.resize(count);
    settings.resize(count);
    shards.resize(count);
    jobs.resize(count);
    held.assign(count, 0);
    all_held = 0;
    for (size_t i = 0; i < count && !run.shard && count > 1; ++i)
      all_held += held[i] = held_bytes(s, plan.volumes[i].placed.desc);
  };
  size_for_plan();
  if (run.shard) run.shard->volumes_out->assign(plan.volumes.size(), DdgiShard{});
  // Volume 0 builds the set-up the others read, so their run contexts are made after its bake.
  const auto job = [&](size_t i) {
    const PlannedVolume& planned = plan.volumes[i];
    settings[i] = planned_volume_settings(s, planned);
    DdgiVolumeJob& j = jobs[i];
    j.settings = &settings[i];
    RunContext& r = j.run;
    r = first;
    r.placed = &planned.placed;
    r.held_bytes = run.held_bytes + all_held - held[i];
    if (run.shard) {
      shards[i] = *run.shard;
      shards[i].first_block = first_blocks[i];
      shards[i].total_blocks = total_blocks;
      shards[i].out = &(*run.shard->volumes_out)[i];
      r.shard = &shards[i];
    }
    if (plan.volumes.size() > 1 || refine_beside) r.file_stream = nullptr;  // the stream predicts a file of one volume
    if (i > 0) {
      BakeSetup& built = *first.setup_out;
      r.prepared = run.prepared ? run.prepared : built.prepared.get();
      r.texture_lod = run.texture_lod ? run.texture_lod : &built.lod;
      r.gpu_session = run.gpu_session ? run.gpu_session : built.gpu.get();
      r.vulkan_warmup = r.gpu_session ? nullptr : run.vulkan_warmup;
      if (!r.voxels && !built.voxels.empty()) r.voxels = &built.voxels;
      r.setup_out = nullptr;  // nothing left to build: the bake's own, freed with it
    }
    BakedVolume& v = out[i];
    v.kind = planned.kind;
    v.given_index = planned.given_index;
    v.why = planned.why;
    j.result = &v.result;
    j.report = &v.report;
    // A refined volume's grid and memory lines would repeat for every one; the summary lists them.
    j.ctx = ctx;
    if (planned.kind == VolumeKind::Refined) j.ctx.info = nullptr, r.warn_black = false;
  };
  job(0);
  std::unique_ptr<RefinementBeside> refinement;
  if (refine_beside) {
    jobs[0].run.held_bytes += refine_bytes;
    refinement = std::make_unique<RefinementBeside>(scene, s, vs, plan, run.prepared, ctx);
  }
  const Status first_baked = bake_ddgi(scene, settings[0], jobs[0].run, jobs[0].ctx, out[0].result, out[0].report);
  const Status refined = refinement ? refinement->join(plan) : Status::ok();
  GIBAKE_TRY(first_baked);
  GIBAKE_TRY(refined);
  if (refinement) size_for_plan();
  const size_t count = plan.volumes.size();
  for (size_t i = 1; i < count; ++i) job(i);
  if (count > 1) GIBAKE_TRY(bake_ddgi_together(scene, {jobs.begin() + 1, jobs.end()}));
  for (size_t i = 0; i < count && run.shard; ++i) {
    shards[i].out->volume = uint32_t(i);
    shards[i].out->volumes = uint32_t(count);
  }
  note_largest_estimate(s, out, ctx, 1);
  return Status::ok();
}

// A shard's blocks: every volume's placed probes, numbered across the volumes.
void shard_blocks(const VolumePlan& plan, std::vector<uint32_t>& first_blocks, uint32_t& total_blocks) {
  first_blocks.clear();
  total_blocks = 0;
  for (const PlannedVolume& v : plan.volumes) {
    first_blocks.push_back(total_blocks);
    total_blocks += probe_blocks(uint32_t(v.placed.desc.probe_count()));
  }
}

// The file's settings (volume 0's): the user's grid settings, not the default grid's budget share,
// and the request when it is not the default one. A one-grid bake keeps its settings as they were.
void file_settings(const DdgiSettings& s, const VolumeSettings& vs, std::vector<BakedVolume>& out) {
  if (out.size() == 1 && !vs.customised()) return;
  nlohmann::json j = nlohmann::json::parse(out[0].result.settings_json);
  j["grid"] = nlohmann::json::parse(ddgi_settings_json(s))["grid"];
  if (vs.customised()) j["probe_volumes"] = nlohmann::json::parse(volume_settings_json(vs));
  out[0].result.settings_json = j.dump();
}

}  // namespace

Status bake_ddgi_volumes(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, const RunContext& run,
                         const Context& ctx, std::vector<BakedVolume>& out, std::string* rule_text,
                         std::string* refine_text) {
  out.clear();
  // The refinement's voxels and rule need only the default grid's placement: they run beside the
  // first volume's bake (a shard plans every volume first, since its blocks are numbered across them).
  const bool refine_beside = !run.shard && refines_default_grid(s.grid, vs.refine);
  VolumePlan plan;
  GIBAKE_TRY(plan_ddgi_volumes(scene, s, vs, ctx, plan, run.prepared, !refine_beside));
  uint64_t refine_bytes = 0;
  if (refine_beside && !plan.volumes.empty() && plan.volumes[0].kind == VolumeKind::Default)
    GIBAKE_TRY(
        refinement_voxel_bytes(scene, plan.volumes[0].placed.desc, s.blend_cutoff, s.max_memory_bytes, refine_bytes));
  std::vector<uint32_t> first_blocks;
  uint32_t total_blocks = 0;
  if (run.shard) shard_blocks(plan, first_blocks, total_blocks);
  const auto note_volumes = [&] {
    if (plan.volumes.size() > 1)
      ctx.note("probe volumes: " + std::to_string(plan.volumes.size()) +
               (plan.rule_text.empty() ? "" : "; " + plan.rule_text) +
               (plan.refine_text.empty() ? "" : "; " + plan.refine_text));
  };
  if (!refine_beside) note_volumes();
  // The voxels the default grid was fitted to are the bake's enclosure voxels too (the same bytes as
  // bake_ddgi would build), unless the run context has a grid or the enclosure test is off.
  const bool fitted = !plan.voxels.empty();
  const bool enclosure = fitted && setup_settings(s).enclosure_resolution > 0 && !run.voxels;
  BakeSetup local_setup;
  RunContext first = run;
  if (enclosure) first.voxels = &plan.voxels;
  if (!first.setup_out) first.setup_out = &local_setup;
  GIBAKE_TRY(
      bake_planned(scene, s, vs, plan, first, run, ctx, refine_beside, refine_bytes, first_blocks, total_blocks, out));
  if (refine_beside) note_volumes();
  if (rule_text) *rule_text = plan.rule_text;
  if (refine_text) *refine_text = plan.refine_text;
  auto& stages = out[0].report.stage_seconds;
  if (plan.refine_seconds > 0.0)
    stages.insert(stages.begin(),
                  {refine_beside ? "refinement (voxels, rule; beside the first volume)" : "refinement (voxels, rule)",
                   plan.refine_seconds});
  if (fitted) stages.insert(stages.begin(), {"voxelize (grid fit)", plan.voxel_seconds});
  file_settings(s, vs, out);
  // The enclosure grid goes where the bake would have left it (the leak audit reads it).
  if (enclosure && run.setup_out) run.setup_out->voxels = std::move(plan.voxels);
  return Status::ok();
}

Status bake_more_volumes(const Scene& scene, const DdgiSettings& s, const std::vector<PlannedVolume>& planned,
                         const RunContext& ready, const Context& ctx, std::vector<BakedVolume>& out) {
  Context quiet = ctx;  // refined volumes: the summary lists them (bake_planned)
  quiet.info = nullptr;
  // The volumes baked before and the others planned here stay until the write (bake_planned).
  uint64_t all_held = 0;
  for (const BakedVolume& v : out) all_held += held_bytes(s, v.result.desc);
  for (const PlannedVolume& p : planned) all_held += held_bytes(s, p.placed.desc);
  const size_t first_new = out.size();
  std::vector<DdgiSettings> settings(planned.size());
  std::vector<DdgiVolumeJob> jobs(planned.size());
  out.resize(first_new + planned.size());
  for (size_t i = 0; i < planned.size(); ++i) {
    const PlannedVolume& p = planned[i];
    settings[i] = planned_volume_settings(s, p);
    DdgiVolumeJob& j = jobs[i];
    j.settings = &settings[i];
    RunContext& r = j.run;
    r = ready;
    r.placed = &p.placed;
    r.held_bytes = ready.held_bytes + all_held - held_bytes(s, p.placed.desc);
    r.setup_out = nullptr;
    r.file_stream = nullptr;
    r.vulkan_warmup = nullptr;
    r.shard = nullptr;
    r.warn_black = p.kind != VolumeKind::Refined;
    BakedVolume& v = out[first_new + i];
    v.kind = p.kind;
    v.given_index = p.given_index;
    v.why = p.why;
    j.ctx = p.kind == VolumeKind::Refined ? quiet : ctx;
    j.result = &v.result;
    j.report = &v.report;
  }
  GIBAKE_TRY(bake_ddgi_together(scene, jobs));
  note_largest_estimate(s, out, ctx, first_new);
  return Status::ok();
}

}  // namespace gibake
