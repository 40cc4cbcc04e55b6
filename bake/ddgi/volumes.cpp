#include "bake/ddgi/volumes.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "bake/ddgi/shard_bake.h"
#include "bake/voxel/enclosure.h"
#include "io/timer.h"

namespace gibake {

namespace {

Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "probe volumes", what); }

bool automatic_grid(const GridSettings& g) {
  return !g.explicit_bounds && g.spacing == 0.f && g.counts[0] == 0 && g.fit_to_voxels;
}

std::string box_text(const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  char text[160];
  std::snprintf(text, sizeof text, "(%.3g, %.3g, %.3g) to (%.3g, %.3g, %.3g)", double(lo[0]), double(lo[1]),
                double(lo[2]), double(hi[0]), double(hi[1]), double(hi[2]));
  return text;
}

struct PlannedVolume {
  VolumeKind kind = VolumeKind::Default;
  int given_index = -1;
  GridSettings grid;
  std::string why;
};

// The given volumes' grids; those without a spacing take the rule within `share` probes each
// and add their probes to `ruled`.
void plan_given(const VolumeSettings& vs, const GridSettings& base, uint64_t share, uint64_t& ruled,
                std::vector<PlannedVolume>& plan) {
  for (size_t i = 0; i < vs.given.size(); ++i) {
    const GivenVolume& g = vs.given[i];
    float s = g.spacing;
    if (s == 0.f) {
      GridSettings rule = base;
      rule.auto_max_probes = std::max<uint64_t>(1, share);
      s = default_probe_spacing({g.hi[0] - g.lo[0], g.hi[1] - g.lo[1], g.hi[2] - g.lo[2]}, rule);
      ruled += box_grid_probes(g.lo, g.hi, s);
    }
    char why[200];
    std::snprintf(why, sizeof why, "--probe-volume %zu over %s, %s", i + 1, box_text(g.lo, g.hi).c_str(),
                  g.spacing > 0.f ? "its spacing" : "the default spacing rule on its box");
    plan.push_back({VolumeKind::Given, int(i), box_grid_settings(base, g.lo, g.hi, s), why});
  }
}

// Every volume's grid settings, in the file's order, with the budget split (volumes.h).
Status plan_volumes(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, const VoxelGrid* voxels,
                    std::vector<PlannedVolume>& plan, std::string& rule_text) {
  const uint64_t budget = std::max<uint64_t>(1, s.grid.auto_max_probes);
  size_t ruled_given = 0;
  for (const GivenVolume& g : vs.given) ruled_given += g.spacing == 0.f;
  DetailDecision detail;
  if (vs.default_volume && vs.detail_volumes && voxels && automatic_grid(s.grid)) {
    DdgiVolumeDesc whole;
    GIBAKE_TRY(place_probe_grid(scene, s.grid, whole, voxels));
    detail = decide_detail_volume(*voxels, scene.bounds, whole, s.grid, budget / 2 / (ruled_given + 1), vs.rule);
    rule_text = detail.text;
  }
  const size_t ruled_count = ruled_given + (detail.add ? 1 : 0);
  const uint64_t share = ruled_count == 0 ? budget : (vs.default_volume ? budget / 2 : budget) / ruled_count;
  uint64_t ruled = 0;
  if (vs.default_volume) plan.push_back({VolumeKind::Default, -1, s.grid, "the default grid"});
  if (detail.add) {
    ruled += detail.probes;
    plan.push_back({VolumeKind::Detail, -1, box_grid_settings(s.grid, detail.lo, detail.hi, detail.spacing),
                    "detail volume over " + box_text(detail.lo, detail.hi) + ": " + detail.text});
  }
  plan_given(vs, s.grid, share, ruled, plan);
  if (vs.default_volume && ruled > 0 && automatic_grid(s.grid)) {  // the default grid keeps the rest
    plan[0].grid.auto_max_probes = std::max<uint64_t>(budget / 2, budget > ruled ? budget - ruled : 1);
    plan[0].why += ", within " + std::to_string(plan[0].grid.auto_max_probes) + " of the " + std::to_string(budget) +
                   " probes of --probe-budget";
  }
  return Status::ok();
}

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
  for (const GivenVolume& g : vs.given) given.push_back({{"min", g.lo}, {"max", g.hi}, {"spacing", g.spacing}});
  return nlohmann::json{{"default_volume", vs.default_volume},
                        {"detail_volumes", vs.detail_volumes},
                        {"given", given}}
      .dump();
}

const char* volume_kind_name(VolumeKind kind) {
  switch (kind) {
    case VolumeKind::Detail: return "detail";
    case VolumeKind::Given: return "given";
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
  }
  return all.dump();
}

std::string volume_line(size_t index, const BakedVolume& v) {
  const DdgiVolumeDesc& d = v.result.desc;
  char text[200];
  std::snprintf(text, sizeof text, "volume %zu (%s): %dx%dx%d = %d probes, spacing %.3g m, %d active; ", index,
                volume_kind_name(v.kind), d.counts[0], d.counts[1], d.counts[2], d.probe_count(),
                double(min_cell_size(d)), v.report.active);
  return text + v.why;
}

namespace {

// Bakes the planned volumes one after the other; every volume after the first reads what the first
// built (BVH, mips, enclosure voxels, device session) instead of building it again.
// With a shard, `first_blocks[i]`: where volume i's blocks begin among the bake's `total_blocks`.
Status bake_planned(const Scene& scene, const DdgiSettings& s, const std::vector<PlannedVolume>& plan,
                    const RunContext& first, const RunContext& run, const Context& ctx,
                    const std::vector<uint32_t>& first_blocks, uint32_t total_blocks, std::vector<BakedVolume>& out) {
  BakeSetup scratch;
  out.resize(plan.size());
  if (run.shard) run.shard->volumes_out->assign(plan.size(), DdgiShard{});
  for (size_t i = 0; i < plan.size(); ++i) {
    DdgiSettings vsettings = s;
    vsettings.grid = plan[i].grid;
    RunContext r = first;
    DdgiShardRun volume_shard;
    if (run.shard) {
      volume_shard = *run.shard;
      volume_shard.first_block = first_blocks[i];
      volume_shard.total_blocks = total_blocks;
      volume_shard.out = &(*run.shard->volumes_out)[i];
      r.shard = &volume_shard;
    }
    if (plan.size() > 1) r.file_stream = nullptr;  // the stream predicts a file of one volume
    if (i > 0) {
      BakeSetup& built = *first.setup_out;
      r.prepared = run.prepared ? run.prepared : built.prepared.get();
      r.texture_lod = run.texture_lod ? run.texture_lod : &built.lod;
      r.gpu_session = run.gpu_session ? run.gpu_session : built.gpu.get();
      r.vulkan_warmup = r.gpu_session ? nullptr : run.vulkan_warmup;
      r.placement_voxels = nullptr;
      if (!r.voxels && !built.voxels.empty()) r.voxels = &built.voxels;
      r.setup_out = &scratch;
    }
    BakedVolume& v = out[i];
    v.kind = plan[i].kind;
    v.given_index = plan[i].given_index;
    v.why = plan[i].why;
    GIBAKE_TRY(bake_ddgi(scene, vsettings, r, ctx, v.result, v.report));
    if (run.shard) {
      volume_shard.out->volume = uint32_t(i);
      volume_shard.out->volumes = uint32_t(plan.size());
    }
  }
  return Status::ok();
}

// A shard's blocks: every volume's probe count, placed as bake_ddgi will place it, before the first
// volume is baked (blocks are numbered across the volumes). `voxels`: the enclosure voxels the
// default grid is fitted to (null: built here when a grid needs them, as bake_ddgi would).
Status shard_blocks(const Scene& scene, const DdgiSettings& s, const std::vector<PlannedVolume>& plan,
                    const VoxelGrid* voxels, const Context& ctx, std::vector<uint32_t>& first_blocks,
                    uint32_t& total_blocks) {
  VoxelGrid own;
  first_blocks.clear();
  total_blocks = 0;
  for (const PlannedVolume& v : plan) {
    const VoxelGrid* fit = nullptr;
    if (automatic_grid(v.grid) && !scene.bounds.empty()) {
      if (!voxels && own.empty()) {
        SetupSettings setup = setup_settings(s);
        if (setup.enclosure_resolution <= 0) setup.enclosure_resolution = 128;
        GIBAKE_TRY(make_enclosure_voxels(scene, setup, ctx, own));
      }
      fit = voxels ? voxels : &own;
    }
    DdgiVolumeDesc desc;
    GIBAKE_TRY(place_probe_grid(scene, v.grid, desc, fit));
    first_blocks.push_back(total_blocks);
    total_blocks += probe_blocks(uint32_t(desc.probe_count()));
  }
  return Status::ok();
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
                         const Context& ctx, std::vector<BakedVolume>& out, std::string* rule_text) {
  out.clear();
  GIBAKE_TRY(validate_volume_settings(vs));
  const bool rule = vs.default_volume && vs.detail_volumes && automatic_grid(s.grid) && !scene.bounds.empty();
  if (vs.default_volume && vs.given.empty() && !rule) {  // one grid, as before volumes existed
    out.resize(1);
    out[0].why = "the default grid";
    if (!run.shard) return bake_ddgi(scene, s, run, ctx, out[0].result, out[0].report);
    run.shard->volumes_out->assign(1, DdgiShard{});
    DdgiShardRun one = *run.shard;
    one.first_block = one.total_blocks = 0;
    one.out = &run.shard->volumes_out->front();
    RunContext r = run;
    r.shard = &one;
    return bake_ddgi(scene, s, r, ctx, out[0].result, out[0].report);
  }
  // The enclosure voxels the default grid is fitted to, built once for the fit, the rule and every
  // volume's enclosure test (as bake_ddgi would build them: the same bytes).
  SetupSettings setup = setup_settings(s);
  const bool enclosure = setup.enclosure_resolution > 0;
  if (!enclosure) setup.enclosure_resolution = 128;
  VoxelGrid voxels;
  const auto t0 = Clock::now();
  if (rule) GIBAKE_TRY(make_enclosure_voxels(scene, setup, ctx, voxels));
  const double voxel_seconds = seconds_since(t0);
  std::vector<PlannedVolume> plan;
  std::string text;
  GIBAKE_TRY(plan_volumes(scene, s, vs, rule ? &voxels : nullptr, plan, text));
  if (rule_text) *rule_text = text;
  std::vector<uint32_t> first_blocks;
  uint32_t total_blocks = 0;
  if (run.shard) GIBAKE_TRY(shard_blocks(scene, s, plan, rule ? &voxels : nullptr, ctx, first_blocks, total_blocks));
  if (plan.size() > 1) ctx.note("probe volumes: " + std::to_string(plan.size()) + (text.empty() ? "" : "; " + text));

  BakeSetup local_setup;
  RunContext first = run;
  if (rule) {
    first.placement_voxels = &voxels;
    if (!run.voxels && enclosure) first.voxels = &voxels;
  }
  if (!first.setup_out) first.setup_out = &local_setup;
  GIBAKE_TRY(bake_planned(scene, s, plan, first, run, ctx, first_blocks, total_blocks, out));
  if (rule) out[0].report.stage_seconds.insert(out[0].report.stage_seconds.begin(), {"voxelize (grid fit)", voxel_seconds});
  file_settings(s, vs, out);
  // The enclosure grid goes where the bake would have left it (the leak audit reads it).
  if (rule && !run.voxels && enclosure && run.setup_out) run.setup_out->voxels = std::move(voxels);
  return Status::ok();
}

}  // namespace gibake
