#include "bake/ddgi/volume_plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/ddgi/detail_volume.h"
#include "bake/run/bake_setup.h"
#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/voxel/enclosure.h"
#include "io/timer.h"

namespace gibake {

namespace {

bool automatic_grid(const GridSettings& g) {
  return !g.explicit_bounds && g.spacing == 0.f && g.counts[0] == 0 && g.fit_to_voxels;
}

std::string box_text(const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  char text[160];
  std::snprintf(text, sizeof text, "(%.3g, %.3g, %.3g) to (%.3g, %.3g, %.3g)", double(lo[0]), double(lo[1]),
                double(lo[2]), double(hi[0]), double(hi[1]), double(hi[2]));
  return text;
}

// Given volumes without a spacing: they take the default rule within a share of the budget.
size_t ruled_given_count(const VolumeSettings& vs) {
  return size_t(std::count_if(vs.given.begin(), vs.given.end(), [](const GivenVolume& g) { return g.spacing == 0.f; }));
}

PlannedVolume planned(VolumeKind kind, int given_index, const GridSettings& grid, std::string why) {
  PlannedVolume v;
  v.kind = kind;
  v.given_index = given_index;
  v.grid = grid;
  v.why = std::move(why);
  return v;
}

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
    std::snprintf(why, sizeof why, "--probe-volume %zu over %s, %s%s", i + 1, box_text(g.lo, g.hi).c_str(),
                  g.spacing > 0.f ? "its spacing" : "the default spacing rule on its box",
                  g.near_surfaces ? ", probes near surfaces only" : "");
    plan.push_back(planned(VolumeKind::Given, int(i), box_grid_settings(base, g.lo, g.hi, s), why));
    if (g.near_surfaces) plan.back().near_surface_reach = kNearSurfaceSpacings * s;
  }
}

// Every volume's grid settings, in the file's order, with the budget split (volumes.h); `cut`: the
// default grid's budget was cut for the other volumes.
void plan_settings(const DdgiSettings& s, const VolumeSettings& vs, const DetailDecision& detail,
                   std::vector<PlannedVolume>& plan, bool& cut) {
  const uint64_t budget = std::max<uint64_t>(1, s.grid.auto_max_probes);
  const size_t ruled_count = ruled_given_count(vs) + (detail.add ? 1 : 0);
  const uint64_t share = ruled_count == 0 ? budget : (vs.default_volume ? budget / 2 : budget) / ruled_count;
  uint64_t ruled = 0;
  if (vs.default_volume) plan.push_back(planned(VolumeKind::Default, -1, s.grid, "the default grid"));
  if (detail.add) {
    ruled += detail.probes;
    plan.push_back(planned(VolumeKind::Detail, -1, box_grid_settings(s.grid, detail.lo, detail.hi, detail.spacing),
                           "detail volume over " + box_text(detail.lo, detail.hi) + ": " + detail.text));
  }
  plan_given(vs, s.grid, share, ruled, plan);
  cut = vs.default_volume && ruled > 0 && automatic_grid(s.grid);
  if (cut) {  // the default grid keeps the rest
    plan[0].grid.auto_max_probes = std::max<uint64_t>(budget / 2, budget > ruled ? budget - ruled : 1);
    plan[0].why += ", within " + std::to_string(plan[0].grid.auto_max_probes) + " of the " + std::to_string(budget) +
                   " probes of --probe-budget";
  }
}

// The detail-volume rule, on the default grid as the whole budget places it (`whole`).
Status decide_detail(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, const VoxelGrid& voxels,
                     PlacedGrid& whole, DetailDecision& detail) {
  const uint64_t budget = std::max<uint64_t>(1, s.grid.auto_max_probes);
  GIBAKE_TRY(place_probe_grid(scene, s.grid, &voxels, whole));
  detail = decide_detail_volume(voxels, scene.bounds, whole.desc, s.grid, budget / 2 / (ruled_given_count(vs) + 1),
                                vs.rule);
  return Status::ok();
}

// The enclosure voxels the default grid is fitted to, as bake_ddgi builds them (the same bytes).
Status build_voxels(const Scene& scene, const DdgiSettings& s, const Context& ctx, VolumePlan& plan) {
  SetupSettings setup = setup_settings(s);
  if (setup.enclosure_resolution <= 0) setup.enclosure_resolution = 128;
  const auto t0 = Clock::now();
  GIBAKE_TRY(make_enclosure_voxels(scene, setup, ctx, plan.voxels));
  plan.voxel_seconds = seconds_since(t0);
  return Status::ok();
}

// A volume other than the default grid as refinement reads it: its cell box and finest spacing.
FinerVolume finer_volume(const DdgiVolumeDesc& d) {
  FinerVolume f;
  for (int a = 0; a < 3; ++a) {
    f.lo[a] = d.grid_min[a] - 0.5f * d.spacing[a];
    f.hi[a] = d.grid_max[a] + 0.5f * d.spacing[a];
  }
  f.spacing = min_cell_size(d);
  return f;
}

std::vector<FinerVolume> finer_volumes(const std::vector<PlannedVolume>& volumes) {
  std::vector<FinerVolume> finer;
  for (const PlannedVolume& v : volumes)
    if (v.kind != VolumeKind::Default) finer.push_back(finer_volume(v.placed.desc));
  return finer;
}

// One refined volume per box of `d`, placed, appended to `out` with the refinement's ray budget;
// each one's why is "refined over BOX: N bricks " + `reason` with the box's contrast (%.3g) in it.
Status add_refined_volumes(const Scene& scene, const GridSettings& grid, const RefineSettings& refine,
                           const RefineDecision& d, const char* reason, std::vector<PlannedVolume>& out) {
  for (const RefinedBox& b : d.boxes) {
    char tail[160], why[320];
    std::snprintf(tail, sizeof tail, reason, double(b.contrast));
    std::snprintf(why, sizeof why, "refined over %s: %u bricks %s", box_text(b.lo, b.hi).c_str(), b.bricks, tail);
    PlannedVolume v = planned(VolumeKind::Refined, -1, box_grid_settings(grid, b.lo, b.hi, d.spacing), why);
    v.ray_budget = refine.ray_budget;
    GIBAKE_TRY(place_probe_grid(scene, v.grid, nullptr, v.placed));
    out.push_back(std::move(v));
  }
  return Status::ok();
}

// Whether the plan's default grid is refined, by the direct light or by the bake's check.
bool refines_plan(const DdgiSettings& s, const VolumeSettings& vs, const VolumePlan& plan) {
  return (refines_default_grid(s.grid, vs.refine) || vs.check_budget != 0) && !plan.volumes.empty() &&
         plan.volumes[0].kind == VolumeKind::Default;
}

// The view volumes (view_volume.h) after the others planned so far. Their rays need an Embree
// scene: the bake's, or one built here.
Status plan_views(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, const Context& ctx,
                  const PreparedScene* prepared, VolumePlan& plan) {
  if (vs.views.empty() || plan.volumes.empty() || scene.bounds.empty()) return Status::ok();
  std::unique_ptr<PreparedScene> own;
  if (!prepared) {
    GIBAKE_TRY(PreparedScene::create(scene, ctx, own));
    prepared = own.get();
  }
  std::vector<SpacedBox> before;
  for (const PlannedVolume& v : plan.volumes) {
    const FinerVolume f = finer_volume(v.placed.desc);
    SpacedBox b{f.lo, f.hi, f.spacing};
    for (int a = 0; a < 3; ++a)  // an axis of one probe is read at any coordinate along it
      if (v.placed.desc.counts[a] < 2) b.lo[a] = -INFINITY, b.hi[a] = INFINITY;
    before.push_back(b);
  }
  for (const ViewCamera& view : vs.views) {
    const ViewVolumeDecision d = decide_view_volume(*prepared, view, before, vs.view_spacing);
    if (!d.add) {
      ctx.warning(d.text);
      continue;
    }
    PlannedVolume v = planned(VolumeKind::View, -1, box_grid_settings(s.grid, d.lo, d.hi, d.spacing), d.text);
    v.near_surface_reach = kNearSurfaceSpacings * d.spacing;
    GIBAKE_TRY(place_probe_grid(scene, v.grid, nullptr, v.placed));
    plan.volumes.push_back(std::move(v));
  }
  return Status::ok();
}

// One miss depth for every volume of the bake (miss_depth): over the planned grids and, where the
// default grid is refined, over its cell box, which holds every refined grid (refined boxes are
// whole bricks of it), so that the depth is known before any refinement runs.
void share_miss_depth(const Scene& scene, bool refined, std::vector<PlannedVolume>& planned) {
  std::vector<const DdgiVolumeDesc*> grids;
  for (const PlannedVolume& v : planned)
    if (v.kind != VolumeKind::Refined) grids.push_back(&v.placed.desc);
  DdgiVolumeDesc cells;
  if (refined) {
    cells = planned[0].placed.desc;
    for (int a = 0; a < 3; ++a) {
      cells.grid_min[a] -= 0.5f * cells.spacing[a];
      cells.grid_max[a] += 0.5f * cells.spacing[a];
    }
    grids.push_back(&cells);
  }
  const float depth = miss_depth(scene.bounds, grids);
  for (PlannedVolume& v : planned) v.placed.desc.max_distance = depth;
}

}  // namespace

Status plan_check_refined(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs,
                          const std::vector<BakedVolume>& baked, const std::vector<CheckMiss>& misses,
                          std::vector<PlannedVolume>& out, std::string& text) {
  out.clear();
  text.clear();
  if (vs.check_budget == 0 || baked.empty() || baked[0].kind != VolumeKind::Default) return Status::ok();
  std::vector<FinerVolume> finer;
  for (size_t i = 1; i < baked.size(); ++i) finer.push_back(finer_volume(baked[i].result.desc));
  RefineDecision d;
  decide_check_refinement(baked[0].result.desc, finer, misses, vs.check_budget, vs.refine, d);
  text = d.text;
  GIBAKE_TRY(
      add_refined_volumes(scene, s.grid, vs.refine, d, "where the bake's check missed (summed error %.3g)", out));
  for (PlannedVolume& v : out) v.placed.desc.max_distance = baked[0].result.desc.max_distance;  // the bake's one depth
  return Status::ok();
}

DdgiSettings planned_volume_settings(const DdgiSettings& s, const PlannedVolume& v) {
  DdgiSettings out = with_ray_budget(s, v.ray_budget);
  out.grid = v.grid;
  out.near_surface_reach = v.near_surface_reach;
  return out;
}

bool refines_default_grid(const GridSettings& grid, const RefineSettings& refine) {
  return refine.budget != 0 && (automatic_grid(grid) || refine.any_grid);
}

bool fitted_default_grid(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs) {
  return vs.default_volume && automatic_grid(s.grid) && !scene.bounds.empty();
}

// The refined volumes go after the others, with the plan's miss depth.
Status plan_refinement(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, const Context& ctx,
                       VolumePlan& plan, const PreparedScene* prepared) {
  if (!refines_default_grid(s.grid, vs.refine) || plan.volumes.empty() || plan.volumes[0].kind != VolumeKind::Default)
    return Status::ok();
  RefineDecision d;
  GIBAKE_TRY(decide_refinement(scene, shade_lights(scene, s.suns), prepared, plan.volumes[0].placed.desc,
                               finer_volumes(plan.volumes), s.blend_cutoff, s.max_memory_bytes, vs.refine, ctx, d));
  plan.refine_text = d.text;
  plan.refine_seconds = d.seconds;
  const size_t first = plan.volumes.size();
  GIBAKE_TRY(add_refined_volumes(scene, s.grid, vs.refine, d,
                                 "where the direct light changes (by up to %.3g cd/m2) or around them", plan.volumes));
  for (size_t i = first; i < plan.volumes.size(); ++i)
    plan.volumes[i].placed.desc.max_distance = plan.volumes[0].placed.desc.max_distance;
  return Status::ok();
}

Status plan_ddgi_volumes(const Scene& scene, const DdgiSettings& s, const VolumeSettings& vs, const Context& ctx,
                         VolumePlan& plan, const PreparedScene* prepared, bool refine) {
  plan = VolumePlan{};
  GIBAKE_TRY(validate_volume_settings(vs));
  GIBAKE_TRY(validate_ddgi_settings(s));
  const bool fitted = fitted_default_grid(scene, s, vs);
  if (fitted) GIBAKE_TRY(build_voxels(scene, s, ctx, plan));
  // The rule judges the grid the whole budget places; the default grid is that grid unless the
  // budget is then cut for the other volumes, when it is placed again with its share.
  const bool rule = fitted && vs.detail_volumes;
  PlacedGrid whole;
  DetailDecision detail;
  if (rule) GIBAKE_TRY(decide_detail(scene, s, vs, plan.voxels, whole, detail));
  plan.rule_text = detail.text;
  bool cut = false;
  plan_settings(s, vs, detail, plan.volumes, cut);
  for (size_t i = 0; i < plan.volumes.size(); ++i) {
    PlannedVolume& v = plan.volumes[i];
    if (i == 0 && rule && !cut) {
      v.placed = whole;
      continue;
    }
    const bool fit = fitted && v.kind == VolumeKind::Default;
    GIBAKE_TRY(place_probe_grid(scene, v.grid, fit ? &plan.voxels : nullptr, v.placed));
  }
  GIBAKE_TRY(plan_views(scene, s, vs, ctx, prepared, plan));
  if (!plan.volumes.empty()) share_miss_depth(scene, refines_plan(s, vs, plan), plan.volumes);
  return refine ? plan_refinement(scene, s, vs, ctx, plan, prepared) : Status::ok();
}

}  // namespace gibake
