// Probe grid placement. Index order: x fastest, then y, then z (index = x + X*(y + Y*z)).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/ddgi/probe_fit.h"
#include "io/results/ddgi_result.h"
#include "io/results/voxel_grid.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

// Without explicit bounds the (padded) scene box is cut into cells and one probe sits at the
// centre of each, so no probe lies on the box's outer walls. With the default rule and voxels the
// box is first fitted to where probes are useful (probe_fit.h) and the rule runs on the fitted box,
// (the probes it saves are not spent on a finer grid: adaptive rays buy more). The default spacing (no --probe-spacing,
// no --probe-counts) is the scene's longest side / auto_cells, kept within [min(auto_min_spacing,
// longest / auto_min_cells), auto_max_spacing] (probes are for diffuse light, which varies over the
// gaps between objects, not over millimetres nor kilometres; a model smaller than auto_min_cells x
// auto_min_spacing still gets auto_min_cells cells along its longest side), then widened until at
// most auto_max_probes probes (--probe-budget) fit. The 1 m cap: a building's
// rooms and arcades need probes about a metre apart to hold their light, and a coarser grid on a
// large scene leaves most surfaces far from the path-traced truth. Rooms between 6 and 24 m get
// longest / 24: with the noise under the ray budget, the spacing is what limits them
// (docs/BENCHMARKS.md "A ray budget" has the figures for both rules).
struct GridSettings {
  float padding = 0.f;                 // metres added to every side of the scene bounds (or the fitted box)
  float spacing = 0.f;                 // > 0: probe spacing (m); counts derived per axis
  std::array<int32_t, 3> counts{};     // all > 0: probes per axis over the (padded or explicit) box
  bool explicit_bounds = false;        // grid_min/grid_max given (needs counts)
  std::array<float, 3> grid_min{}, grid_max{};
  int32_t auto_cells = 24;             // default spacing: cells along the longest side
  float auto_min_spacing = 0.25f;      // metres (models smaller than auto_min_cells x this: less)
  int32_t auto_min_cells = 8;          // cells along the longest side of a small model
  float auto_max_spacing = 1.f;        // metres (architectural scenes: a probe a metre, within the budget)
  uint64_t auto_max_probes = 32768;    // --probe-budget
  bool fit_to_voxels = true;           // default rule with voxels: fit the box first (bake/ddgi/probe_fit.h)
  uint64_t max_probes = uint64_t(1) << 21;
};

// The default spacing for a box of these extents (metres), by the rule above; the budget counts
// the cells as placement lays them on a box `fitted` to the voxels or not (cells_along).
float default_probe_spacing(const std::array<float, 3>& extent, const GridSettings& settings, bool fitted = false);
// Cells along an extent at a spacing: enough to cover it, or on a fitted box (which ends at walls)
// as many as keep the outermost probes between a quarter and three quarters of a spacing inside it.
double cells_along(float extent, float spacing, bool fitted);

// What the placement did beyond the rule: the box fit and what the grid would have been without it.
struct GridPlacement {
  BoxFit fit;                       // fit.fitted: the default rule ran on fit.lo..fit.hi
  uint64_t unfitted_probes = 0;     // probes of the default rule on the whole (padded) scene box
  float unfitted_spacing = 0.f;     // ... and its spacing (m)
  // Sides (-x, +x, -y, +y, -z, +z) that got one layer of probes outside the box, a spacing beyond
  // the cell-centred lattice: the box's open sides (probe_fit.h), when the budget allows.
  std::array<bool, 6> outer_layer{};
};

// Fills desc.grid_min/grid_max/counts/spacing. Errors (BadArguments) for empty scenes without
// explicit bounds, non-positive values, or more than max_probes probes. With the default rule (no
// spacing, counts or bounds given), settings.fit_to_voxels and `voxels` covering the scene, the
// padded scene box is first fitted to where probes are useful (bake/ddgi/probe_fit.h) and the
// default spacing is derived on the fitted box; `placement` (optional) says what the fit did.
Status place_probe_grid(const Scene& scene, const GridSettings& settings, DdgiVolumeDesc& desc,
                        const VoxelGrid* voxels = nullptr, GridPlacement* placement = nullptr);

// A volume's grid as placed, with what the placement did: placed once per bake by the volume plan
// (bake/ddgi/volume_plan.h) and read by the bake, the shard's block count and inspect.
// The depth a bake records for rays that hit nothing (DdgiVolumeDesc::max_distance, unless
// DdgiSettings::max_distance sets it): 1.5 x the diagonal of the scene's bounds and every grid's
// together, at least 1 m. The volumes of one bake share it (plan_ddgi_volumes), so a miss reads
// the same depth in each and their probes can be traced in one stage.
float miss_depth(const Bounds& scene, const std::vector<const DdgiVolumeDesc*>& grids);

struct PlacedGrid {
  DdgiVolumeDesc desc;      // grid_min/grid_max, counts and spacing (the rest is the bake's)
  GridPlacement placement;  // what the default grid's fit did (the bake's grid line prints it)
};
inline Status place_probe_grid(const Scene& scene, const GridSettings& settings, const VoxelGrid* voxels,
                               PlacedGrid& out) {
  out = PlacedGrid{};
  return place_probe_grid(scene, settings, out.desc, voxels, &out.placement);
}

// One line on what the fit did ("" when the box was not fitted): the sides dropped, how far and
// why, and the probes the rule would have placed on the whole box.
std::string placement_text(const GridPlacement& placement);

// Rest position of probe `index`.
std::array<float, 3> probe_rest_position(const DdgiVolumeDesc& desc, int32_t index);

// Smallest spacing over axes with more than one probe (0 when every axis has one probe).
float min_cell_size(const DdgiVolumeDesc& desc);

}  // namespace gibake
