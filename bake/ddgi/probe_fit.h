// Fitting the default probe grid's box to where probes are useful, from the enclosure voxels
// (occupancy and the flood fill, bake/voxel/enclosure.h), before any probe is placed.
//
// A voxel of the scene box is useful for a probe when it is open space the flood fill reaches
// (Exterior; Surface is inside geometry, Interior is closed space: inside solids and sealed rooms)
// and it is not below the lowest floor (its column has a surface above it but none below). When
// the scene encloses space (at least half of that open space lies between surfaces along x, along
// z and above a surface below: courts, rooms, arcades), open space outside the enclosure (beside or
// above the building, above the closed wings' roofs) is not useful either. The fitted box is the
// bounding box of the useful voxels (whole voxels) grown by one voxel, within the scene box: the
// surfaces that bound the useful space (the floor, the walls) lie in the voxels just outside it, and
// the grid's cell box must hold them, or the sampler reads them clamped from probes a voxel and
// more away. Slabs beyond that are dropped, except on a side that would lose at most 1.5 voxels
// (the wall the box already ends at). When no voxel is useful (a sealed room, a closed model) the
// box stays.
//
// A side the fit keeps at the scene box is *open* when the scene box's outermost voxel slab on that
// side holds open space that continues inwards (the voxel inside it open too) and surface voxels,
// each at least 1% of the slab: walls, rims or edges that end at the scene's bounds beside open
// space, whose faces there look out of the scene (cornell-box-nvpro's open front, where the walls'
// front faces face the camera; the extremities of a model). No probe of a lattice inside the box
// stands in front of such a face, so the sampler would read it from probes behind it, which see
// the inside; the placement puts one layer of probes outside an open side (probe_grid.h).
#pragma once
#include <array>
#include <cstdint>

#include "io/results/voxel_grid.h"

namespace gibake {

enum class SlabReason : uint8_t {
  Kept = 0,    // nothing dropped on this side
  Solid,       // inside geometry or closed space
  BelowFloor,  // below the lowest floor
  Outside,     // open space outside the scene's enclosure
};
const char* slab_reason_text(SlabReason reason);

struct BoxFit {
  bool fitted = false;              // some slab was dropped
  bool enclosed = false;            // the scene encloses space (the "outside" rule applied)
  std::array<float, 3> lo{}, hi{};  // the fitted box, metres (the input box when not fitted)
  // Metres dropped and why, per side: -x, +x, -y, +y, -z, +z: what most of the dropped voxels were.
  std::array<float, 6> dropped{};
  std::array<SlabReason, 6> why{};
  // Sides of the scene box (not dropped) that are open, as above.
  std::array<bool, 6> open{};
  // Voxels of the scene box by what they are (for the summary).
  uint64_t useful = 0, solid = 0, below_floor = 0, outside = 0;
};

// Fits the box [lo, hi] (the scene bounds) with `voxels` covering it.
BoxFit fit_probe_box(const VoxelGrid& voxels, const std::array<float, 3>& lo, const std::array<float, 3>& hi);

}  // namespace gibake
