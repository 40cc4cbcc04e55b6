// Probe classification: a probe that sees back faces on more than `backface_threshold` of its
// rays is inside geometry and becomes Inactive. Where the mesh has closed components the
// verdict is cross-checked with CGAL (ClosedMeshInsideTester) and disagreements are counted.
#pragma once
#include <cstdint>
#include <mutex>
#include <vector>

#include "io/inspect/mesh_diagnostics.h"
#include "io/results/ddgi_result.h"
#include "io/results/voxel_grid.h"
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

// The closed-mesh cross-check split in two, so that its costly half (welding the whole scene and
// finding its closed components) can run beside the trace, before any probe's rays are known.
// CGAL's mesh and tree are then built only for the solids whose box holds a probe that saw back
// faces (SolidBuild::on_demand): the answers of a tester with every solid built. Those near a
// probe can be built beside the trace too, so the report after it has only queries left.
class ClosedMeshCheck {
 public:
  ClosedMeshCheck() = default;  // no solids: report() says closed_mesh_checked = false
  explicit ClosedMeshCheck(const Scene& scene);
  // The same, and the solids the probes may ask about built now too: those whose box, grown by
  // `pad`, holds a probe's rest position (probe_count*3 floats; pad: the relocation's reach).
  ClosedMeshCheck(const Scene& scene, const std::vector<float>& rest_positions, const float pad[3]);
  // The same on the scene's solids found once for every volume of a bake (SharedClosedMeshes),
  // which must outlive this check: the same answers, without welding the scene again.
  ClosedMeshCheck(const ClosedMeshInsideTester& shared, const std::vector<float>& rest_positions, const float pad[3]);
  // The report for the probes at `positions` whose rays saw back faces; `states` are the ray
  // test's verdicts.
  ClassifyReport report(const std::vector<float>& positions, const std::vector<DdgiProbeStats>& stats,
                        const std::vector<ProbeState>& states) const;

 private:
  const ClosedMeshInsideTester& tester() const { return shared_ ? *shared_ : own_; }
  ClosedMeshInsideTester own_;
  const ClosedMeshInsideTester* shared_ = nullptr;
};

// The scene's closed components, welded and found once for all the DDGI volumes of a bake (a
// refined bake has dozens, and each would otherwise weld the whole scene again beside its short
// trace). Built by the first volume that asks, from any thread; solids are built on demand.
class SharedClosedMeshes {
 public:
  const ClosedMeshInsideTester& tester(const Scene& scene) const;

 private:
  mutable std::once_flag once_;
  mutable ClosedMeshInsideTester tester_;
};

// The ray test's states: Inactive above the back-face threshold, Active otherwise.
void ray_test_states(const std::vector<DdgiProbeStats>& stats, float backface_threshold, std::vector<ProbeState>& states);

// positions: probe_count*3 world positions (rest + offset). Writes states; with use_cgal, the
// closed-mesh check is built and reported here.
ClassifyReport classify_probes(const Scene& scene, const std::vector<float>& positions,
                               const std::vector<DdgiProbeStats>& stats, float backface_threshold,
                               bool use_cgal, std::vector<ProbeState>& states);

}  // namespace gibake
