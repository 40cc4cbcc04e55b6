// The plan of a DDGI bake's volumes (volumes.h): which volumes there are, each one's grid settings
// with the probe budget split, and each one's grid placed. Every final grid is placed here, once
// per bake; the bake of each volume (RunContext::placed), the shard's block numbering and
// `gibake inspect` read the placed grids instead of placing them again.
#pragma once
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/probe_grid.h"
#include "bake/ddgi/volumes.h"
#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct PlannedVolume {
  VolumeKind kind = VolumeKind::Default;
  int given_index = -1;  // Given: which --probe-volume (0-based)
  GridSettings grid;     // its settings (the default grid's with its budget share)
  std::string why;       // one line: why the volume exists
  PlacedGrid placed;     // its grid, placed from `grid`
  uint32_t ray_budget = 0;  // rays its probes average; 0: the bake's settings (refined volumes: RefineSettings)
  float near_surface_reach = 0.f;  // DdgiSettings::near_surface_reach (a --probe-volume ...:near)
};

// The settings volume `v` is baked with: the bake's, with the volume's grid and its own ray budget
// where it has one (with_ray_budget, ddgi.h).
DdgiSettings planned_volume_settings(const DdgiSettings& settings, const PlannedVolume& v);

struct VolumePlan {
  // The file's order: the default grid, the detail volume, the given ones, the view volumes
  // (view_volume.h), the refined ones.
  std::vector<PlannedVolume> volumes;
  std::string rule_text;               // what the detail-volume rule found (empty when it did not run)
  std::string refine_text;             // what refinement placed (empty when not asked for; refine.h)
  // The enclosure voxels the default grid was fitted to (empty when no grid is fitted), built as a
  // bake builds them (setup_settings; 128 on the longest side when the enclosure test is off), so
  // that the bake's enclosure test and leak audit can read them; and the seconds they took.
  VoxelGrid voxels;
  double voxel_seconds = 0.0;
  double refine_seconds = 0.0;  // the refinement's voxels and rule (0 when not asked for)
};

// Whether the default grid of these settings is fitted to the enclosure voxels (probe_fit.h): the
// default spacing rule with no bounds, spacing or counts given, on a scene with geometry.
bool fitted_default_grid(const Scene& scene, const DdgiSettings& settings, const VolumeSettings& volumes);

// Whether refinement (refine.h) runs over the default grid of `grid`: a budget, and the spacing
// rule's grid or a budget given for any grid (RefineSettings::any_grid).
bool refines_default_grid(const GridSettings& grid, const RefineSettings& refine);

// Validates both settings, builds the voxels when the default grid is fitted, decides the detail
// volume, splits the budget, places every volume's grid and, with refinement asked for, adds the
// refined volumes over the default grid (refine.h; `prepared`: the bake's Embree scene, or null).
// `refine` false leaves the refined volumes to plan_refinement (a bake runs it beside its first
// volume); every volume's miss depth is set either way. Errors as place_probe_grid's and voxelize's.
Status plan_ddgi_volumes(const Scene& scene, const DdgiSettings& settings, const VolumeSettings& volumes,
                         const Context& ctx, VolumePlan& plan, const PreparedScene* prepared = nullptr,
                         bool refine = true);

// The refined volumes plan_ddgi_volumes(..., refine = false) left out, appended to `plan`.
Status plan_refinement(const Scene& scene, const DdgiSettings& settings, const VolumeSettings& volumes,
                       const Context& ctx, VolumePlan& plan, const PreparedScene* prepared = nullptr);

// Refinement by the bake's check (refine.h): the refined volumes over the default grid `baked[0]`
// where `misses` lie, outside the volumes already baked, within volumes.check_budget probes;
// `text`: one line saying what was placed (empty when not asked for).
Status plan_check_refined(const Scene& scene, const DdgiSettings& settings, const VolumeSettings& volumes,
                          const std::vector<BakedVolume>& baked, const std::vector<CheckMiss>& misses,
                          std::vector<PlannedVolume>& out, std::string& text);

// Bakes `planned` after the volumes of a bake (refinement by check), each on its placed grid, with
// the set-up `ready` holds (prepared scene, texture mips, Vulkan device, voxels); appended to `out`.
Status bake_more_volumes(const Scene& scene, const DdgiSettings& settings, const std::vector<PlannedVolume>& planned,
                         const RunContext& ready, const Context& ctx, std::vector<BakedVolume>& out);

}  // namespace gibake
