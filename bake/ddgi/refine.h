// Adaptive refinement: finer probe volumes where the direct light changes near surfaces.
//
// A probe grid interpolates the light between its probes; where the light that surfaces send back
// changes over less than a spacing (the edge of a sunlit strip, a lamp's pool of light, a lit
// wall meeting a shaded floor), the indirect light near those surfaces changes as fast, and a
// coarse grid blurs it. The rule, decided at plan time so that every shard sees the same plan:
// * The default grid's cell box is cut into bricks of `brick_cells` cells per side.
// * The scene is voxelized at a quarter of the default spacing (at most 512 voxels on its longest
//   side) with the bake's lights (Embree shadow rays, bake/voxel/voxelize.h). Each surface voxel's source radiance is
//   what it sends back of the direct light, luminance(direct × albedo) / π, plus its emission (cd/m²).
// * A brick's contrast is over the surface voxels within one voxel of it (so an edge on a brick
//   face counts for both sides): max − min, when max ≥ 2 min (a change, not a gentle slope), and at
//   least 1% of the largest brick's contrast (dim corners do not spend the budget).
// * A brick ranks by its contrast times w + (1 − w) × its cover, w = `open_sky_weight` and the
//   cover the share of its x/z footprint (in voxel columns) with a surface voxel above it, so a
//   brick under open sky (a roof, an open court's floor) ranks at w of its contrast: what such
//   surfaces send back leaves mostly to the sky, and the light around them comes mostly straight
//   from the sun and sky, which the runtime's direct lighting carries. Under cover (an arcade, a
//   room) the same contrast lights the surfaces facing it, and a coarse grid leaks it across thin
//   occluders (curtains, columns) into the shade.
// * Bricks are taken by that weighted contrast, highest first, then the bricks with surface voxels
//   around them, ring by ring out to `rings` steps (the indirect light changes near where the
//   direct light does), as many as fit: their boxes (bricks merged into boxes, below) at half the default
//   spacing hold at most `budget` probes in at most `max_volumes` volumes (the count found by
//   bisection).
// * Merging: in brick order, a chosen brick not yet in a box starts one, which grows along +x, then
//   +z, then +y while the new slab of bricks is at least half chosen and overlaps no other box.
//   When that makes more than `max_volumes` boxes, boxes grow over slabs a third, then a sixth
//   chosen, and then the same is done on tiles of 2, 4, ... bricks a
//   side (a tile is chosen when a brick in it is), so that scattered bricks cost some probes in
//   air rather than a volume each. Each box becomes one volume (kind "refined") at half the
//   default spacing; the runtime blend (docs/FORMAT.md "Several volumes") gives it full weight over
//   its bricks, finest first.
// Bricks inside a volume already at least as fine (a detail or given volume) are not refined.
// Only lights with a position or direction and emissive surfaces drive the rule; a scene lit only
// by the sky gets no refinement.
//
// Refinement by the bake's check (--refine-by-check), a second pass after the bake: the direct
// light's change does not show where indirect light alone changes faster than the grid follows
// (a shaded wall lit by a sunlit floor), so the bake's own reconstruction check
// (bake/preview/reconstruction_check.h, patches from what the probes see or the check views) is run on the baked
// volumes, and the bricks holding the points of the patches it finds off by more than its
// tolerance (beyond the reference's own noise) are refined the same way: ranked by the summed
// error of their points, merged into boxes on tiles of at most 2 bricks (scattered misses are not
// worth boxes of air: the bricks that do not fit are left), at most `budget` probes. Bricks already
// inside a volume at least as fine are left. It needs every probe baked, so a shard cannot run it.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/context.h"
#include "io/results/ddgi_result.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake {

class PreparedScene;

struct RefineSettings {
  uint64_t budget = 8192;      // probes the refined volumes may hold (--refine-budget); 0: no refinement
  // Rays a refined probe averages (--refine-ray-budget; planned_volume_settings, volume_plan.h);
  // 0: the bake's ray settings. The refined volumes can hold more probes than the grid, and more of
  // them sit under cover, where paths run long: a budget of their own keeps a level within its time.
  uint32_t ray_budget = 1024;
  // Whether a default grid set by spacing, counts or bounds is refined too (--refine-budget given);
  // otherwise only the spacing rule's grid is: a grid the user laid out is left as laid out.
  bool any_grid = false;
  int32_t brick_cells = 2;     // a brick's side, in default-grid cells
  int32_t max_volumes = 48;    // refined volumes, at most
  float min_contrast = 2.f;    // a brick's max / min source radiance, at least
  float min_share = 0.01f;     // a brick's contrast / the largest brick's, at least
  // A brick under open sky (no surface above any of its footprint) ranks at this share of its
  // contrast, one under cover at all of it; 1: sky and cover alike.
  float open_sky_weight = 0.1f;
  int32_t rings = 4;           // bricks near surfaces this many steps from a changing brick follow it
  // The coarsest tile (in bricks a side) boxes may be merged on; 0: any. With a cap, bricks that
  // would need coarser tiles to keep within max_volumes are left out instead of boxed with air.
  int32_t max_tile = 0;
};

// A volume already planned besides the default grid: its cell box and finest spacing.
struct FinerVolume {
  std::array<float, 3> lo{}, hi{};
  float spacing = 0.f;
};

struct RefinedBox {
  std::array<float, 3> lo{}, hi{};  // metres: whole bricks of the default grid's cell box
  uint32_t bricks = 0;              // chosen bricks inside it
  float contrast = 0.f;             // the highest chosen brick's, cd/m²
};

struct RefineDecision {
  float spacing = 0.f;              // the refined volumes' spacing (half the default grid's)
  float brick_size = 0.f;           // a brick's side, metres (the default grid's finest axis)
  std::vector<RefinedBox> boxes;    // one volume each, in brick order
  uint64_t probes = 0;              // in the boxes
  uint64_t surface_bricks = 0;      // bricks with surface voxels near them
  uint64_t candidates = 0;          // bricks whose contrast passes the rule
  uint64_t under_cover = 0;         // of them, those with a surface above most of their footprint
  uint64_t near = 0;                // bricks near surfaces in the rings around them
  uint64_t chosen = 0;              // candidates that fit the budget
  double seconds = 0.0;             // voxelize and decide
  std::string text;                 // one line: what was placed and why (empty: rule not asked for)
};

// A point of a patch the check found off: where it is and how far off its patch was (|ratio - 1|).
struct CheckMiss {
  std::array<float, 3> p{};
  float error = 0.f;
};

// `coarse`: the default grid as placed; `finer`: the other volumes already planned (bricks inside
// one at least as fine are skipped). `prepared` may be null
// (the voxelizer then builds its own Embree scene). Errors as voxelize's, whose voxels are held
// to `max_memory_bytes` (--max-memory).
Status decide_refinement(const Scene& scene, const std::vector<kernels::ShadeLight>& lights,
                         const PreparedScene* prepared, const DdgiVolumeDesc& coarse,
                         const std::vector<FinerVolume>& finer, float blend_cutoff, uint64_t max_memory_bytes,
                         const RefineSettings& settings, const Context& ctx, RefineDecision& out);

// The working set decide_refinement's voxels are estimated at (voxelize's estimate before it
// allocates), so that a bake running the refinement beside another stage can count it there; over
// `max_memory_bytes`, refused as decide_refinement would refuse it.
Status refinement_voxel_bytes(const Scene& scene, const DdgiVolumeDesc& coarse, float blend_cutoff,
                              uint64_t max_memory_bytes, uint64_t& bytes);

// The check's pass: refined boxes over the bricks holding `misses` (a volume has full weight over
// its cell box, so the point is read from it alone), at most `budget` probes in at most
// settings.max_volumes volumes; `finer`: every volume baked besides the default grid.
void decide_check_refinement(const DdgiVolumeDesc& coarse, const std::vector<FinerVolume>& finer,
                             const std::vector<CheckMiss>& misses, uint64_t budget, const RefineSettings& settings,
                             RefineDecision& out);

}  // namespace gibake
