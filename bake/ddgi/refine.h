// Adaptive refinement: finer probe volumes where the direct light changes near surfaces.
//
// A probe grid interpolates the light between its probes; where the light that surfaces send back
// changes over less than a spacing (the edge of a sunlit strip, a lamp's pool of light, a lit
// wall meeting a shaded floor), the indirect light near those surfaces changes as fast, and a
// coarse grid blurs it. The rule, decided at plan time so that every shard sees the same plan:
// * The default grid's cell box is cut into bricks of `brick_cells` cells per side.
// * The scene is voxelized at a quarter of the default spacing (at most 512 voxels on its longest
//   side) with the bake's lights (Embree shadow rays, bake/voxel/voxelize.h). Each surface voxel's source radiance is what it sends back
//   of the direct light, luminance(direct × albedo) / π, plus its emission (cd/m²).
// * A brick's contrast is over the surface voxels within one voxel of it (so an edge on a brick
//   face counts for both sides): max − min, when max ≥ 2 min (a change, not a gentle slope), and at
//   least 1% of the largest brick's contrast (dim corners do not spend the budget).
// * Bricks are taken by contrast, highest first, then the bricks with surface voxels around them,
//   ring by ring out to `rings` steps (the indirect light changes near where the direct light
//   does), as many as fit: their boxes (bricks merged into boxes, below) at half the default
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
  uint64_t budget = 16384;     // probes the refined volumes may hold (--refine-budget); 0: no refinement
  // Whether a default grid set by spacing, counts or bounds is refined too (--refine-budget given);
  // otherwise only the spacing rule's grid is: a grid the user laid out is left as laid out.
  bool any_grid = false;
  int32_t brick_cells = 2;     // a brick's side, in default-grid cells
  int32_t max_volumes = 48;    // refined volumes, at most
  float min_contrast = 2.f;    // a brick's max / min source radiance, at least
  float min_share = 0.01f;     // a brick's contrast / the largest brick's, at least
  int32_t rings = 4;           // bricks near surfaces this many steps from a changing brick follow it
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
  uint64_t near = 0;                // bricks near surfaces in the rings around them
  uint64_t chosen = 0;              // candidates that fit the budget
  double seconds = 0.0;             // voxelize and decide
  std::string text;                 // one line: what was placed and why (empty: rule not asked for)
};

// `coarse`: the default grid as placed; `finer`: the other volumes already planned (bricks inside
// one at least as fine are skipped). `prepared` may be null
// (the voxelizer then builds its own Embree scene). Errors as voxelize's.
Status decide_refinement(const Scene& scene, const std::vector<kernels::ShadeLight>& lights,
                         const PreparedScene* prepared, const DdgiVolumeDesc& coarse,
                         const std::vector<FinerVolume>& finer, float blend_cutoff,
                         const RefineSettings& settings, const Context& ctx, RefineDecision& out);

}  // namespace gibake
