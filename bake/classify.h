// Probe classification: a probe that sees back faces on more than `backface_threshold` of its
// rays is inside geometry and becomes Inactive. Where the mesh has closed components the
// verdict is cross-checked with CGAL (ClosedMeshInsideTester) and disagreements are counted.
#pragma once
#include <cstdint>
#include <vector>

#include "bake/ddgi_result.h"
#include "bake/voxel_grid.h"
#include "io/scene.h"

namespace gibake {

struct ClassifyReport {
  bool closed_mesh_checked = false;  // a closed component existed (and some probe saw back faces)
  uint32_t inside_by_cgal = 0;       // probes CGAL puts strictly inside a closed component
  // Ray verdict != CGAL verdict (CGAL on-surface answers ignored), split by direction:
  uint32_t disagreements = 0;              // CGAL inside a closed solid, rays say active
  uint32_t inactive_outside_closed = 0;    // rays say inactive, CGAL outside every closed solid
                                           // (normal for open geometry, e.g. behind a wall)
};

// True when the point lies in space the voxel grid finds closed off from the outside: an
// Interior voxel, or a Surface voxel none of whose 26 neighbours is Exterior (a probe sitting in
// a voxel that a wall also touches).
bool probe_in_enclosed_space(const VoxelGrid& voxels, const float position[3]);

// positions: probe_count*3 world positions (rest + offset). Writes result.states.
ClassifyReport classify_probes(const Scene& scene, const std::vector<float>& positions,
                               const std::vector<DdgiProbeStats>& stats, float backface_threshold,
                               bool use_cgal, std::vector<ProbeState>& states);

}  // namespace gibake
