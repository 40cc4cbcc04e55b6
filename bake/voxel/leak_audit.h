// Leak audit: where a wall thinner than the probe spacing separates lit from unlit space, probes
// on both sides interpolate across it and light leaks through (or darkness leaks out). Read from
// the voxel grid: walls are what lies between two runs of empty voxels at least one spacing deep
// (room for a probe cell) along an axis, crossed in fewer voxels than the spacing; "lit" is direct visibility of a light or an emissive surface from that space.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/scene/prepare.h"
#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake {

struct LeakAuditSettings {
  float probe_spacing = 0.f;  // metres; walls thinner than this are audited
  int emitter_samples = 16;   // points on emissive triangles tested for visibility
  size_t max_regions = 8;     // the largest regions are reported
};

// One thin wall between lit and unlit space: the wall voxels' bounds, the axis the wall is thin
// along (0 x, 1 y, 2 z), its thickness bound (voxels crossed x voxel size; the true wall is at most
// this thick) and a point on either side.
struct LeakRegion {
  std::array<float, 3> min{0.f, 0.f, 0.f}, max{0.f, 0.f, 0.f};
  int axis = 0;
  float thickness = 0.f;
  uint64_t voxels = 0;
  std::array<float, 3> lit_point{0.f, 0.f, 0.f}, dark_point{0.f, 0.f, 0.f};
  bool dark_enclosed = false;  // the unlit side is Interior space: a closed room, or inside a closed shape
};

struct LeakAudit {
  float probe_spacing = 0.f;
  uint64_t thin_wall_crossings = 0;  // (voxel, axis) walks through walls thinner than the spacing
  uint64_t leak_voxels = 0;          // wall voxels between lit and unlit space
  uint64_t rays = 0;                 // visibility rays traced
  std::vector<LeakRegion> regions;   // largest first, at most max_regions
  uint64_t regions_total = 0;
};

// `prepared` must be built from the scene the grid was made of; `lights` as shade_lights() makes
// them; `emitters` may be empty. Deterministic for any thread count.
Status audit_leaks(const VoxelGrid& grid, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                   const LeakAuditSettings& settings, const Context& ctx, LeakAudit& out);

// One line naming where: "wall at x 1.20..1.26 m, y 0.00..2.00 m, z -1.00..1.00 m (0.06 m thick
// along x, probe spacing 0.25 m) separates lit space (1.1, 1.0, 0.0) from unlit space (1.4, 1.0, 0.0)".
std::string describe_leak(const LeakRegion& region, float probe_spacing);

}  // namespace gibake
