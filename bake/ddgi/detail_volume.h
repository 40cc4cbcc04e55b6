// The automatic detail volume: a building standing on a large ground plane gets one grid
// spread over the ground at the ground's scale and a handful of probes inside the building. When
// the default grid is much coarser than the raised geometry on the ground needs, a second, finer
// volume is fitted around that geometry.
//
// The rule, on the enclosure voxels (bake/voxel/enclosure.h) the default grid was fitted to:
// * Raised voxels are surface voxels more than one voxel above the lowest surface of their column
//   (x, z): walls, roofs, furniture, columns; not a ground plane, not a gentle slope.
// * The cluster is the box of the raised voxels' columns, from the lowest surface under them up
//   to the highest raised voxel (whole voxels, within the scene box).
// * Its spacing is the default spacing rule (probe_grid.h) on the cluster's box alone, within its
//   share of --probe-budget; the box is padded by one of its spacings on every side, below the
//   ground too (the runtime blend, docs/FORMAT.md "Several volumes", fades a volume out over the
//   outer spacing of its cell box, so the cluster, floors and outer walls included, gets the detail
//   volume's full weight; the layer under the ground goes inactive) and cut into cells, one probe at
//   the centre of each, like the default grid.
// * The volume is added when the default grid's spacing is at least min_ratio (2) times the
//   cluster's and the cluster's box is at most max_fraction (1/8) of the default grid's box: a
//   compact cluster on a large, mostly empty ground. Where the raised geometry fills the scene
//   (Sponza, rooms, boxes) the cluster is the whole box and one grid serves.
// One cluster: all raised voxels together (several far-apart buildings give one box, usually too
// large for the rule to fire).
#pragma once
#include <array>
#include <cstdint>
#include <string>

#include "bake/ddgi/probe_grid.h"
#include "io/results/ddgi_result.h"
#include "io/results/voxel_grid.h"
#include "io/scene.h"

namespace gibake {

struct DetailRule {
  float min_ratio = 2.f;         // default grid spacing / the cluster's spacing, at least
  float max_fraction = 0.125f;   // cluster box volume / default grid box volume, at most
};

// The raised voxels' box (found = false when there are none).
struct RaisedCluster {
  bool found = false;
  std::array<float, 3> lo{}, hi{};  // metres, within the scene box
  uint64_t voxels = 0;              // raised voxels
};
RaisedCluster find_raised_cluster(const VoxelGrid& voxels, const Bounds& scene_bounds);

struct DetailDecision {
  bool add = false;
  RaisedCluster cluster;
  std::array<float, 3> lo{}, hi{};  // the detail volume's box (padded cluster), metres
  float spacing = 0.f;              // the cluster's spacing by the rule within its budget
  float default_spacing = 0.f;      // the default grid's coarsest spacing
  float fraction = 0.f;             // cluster box / default grid box (volumes)
  uint64_t probes = 0;              // the detail volume's probes
  std::string text;                 // why it was (or was not) added, one line
};

// `default_desc`: the default grid as placed with the whole budget; `grid`: its settings, whose
// rule (auto_* members) gives the cluster's spacing within `budget` probes.
DetailDecision decide_detail_volume(const VoxelGrid& voxels, const Bounds& scene_bounds,
                                    const DdgiVolumeDesc& default_desc, const GridSettings& grid, uint64_t budget,
                                    const DetailRule& rule = {});

// A grid over the box [lo, hi] at `spacing`: ceil(extent / spacing) cells per axis (at least one), one
// probe at the centre of each, as explicit bounds and counts (the spacing kept exactly).
GridSettings box_grid_settings(const GridSettings& base, const std::array<float, 3>& lo,
                               const std::array<float, 3>& hi, float spacing);
// Probes such a grid has.
uint64_t box_grid_probes(const std::array<float, 3>& lo, const std::array<float, 3>& hi, float spacing);

}  // namespace gibake
