// Mesh diagnostics (degenerate triangles, open and non-manifold edges, closed components,
// optional self-intersections) and an inside/outside tester for closed components.
// Implemented with CGAL in mesh_diagnostics.cpp; this header includes no CGAL.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>

#include "io/scene.h"

namespace gibake {

struct MeshDiagnosticsOptions {
  // Exact pairwise test of every triangle against every other that its box overlaps
  // (CGAL::Polygon_mesh_processing::self_intersections). Slow on large scenes. Triangles that
  // touch without sharing a welded edge or vertex (stacked boxes, parts of different meshes
  // meeting at a point) count as intersecting; exact duplicate triangles and zero-area
  // triangles are left out of this test.
  bool check_self_intersections = false;
};

// All counts are over the whole soup after welding vertices with bit-identical positions
// (+0 and -0 are the same). Edges and components are combinatorial: two triangles are
// neighbours when they share a welded edge.
struct MeshDiagnostics {
  uint64_t triangles = 0;             // input triangles
  uint64_t input_vertices = 0;        // input vertices
  uint64_t welded_vertices = 0;       // distinct positions referenced by triangles
  uint64_t invalid_triangles = 0;     // an index out of range or a non-finite position (ignored)
  uint64_t degenerate_triangles = 0;  // repeated_vertex_triangles + zero_area_triangles
  uint64_t repeated_vertex_triangles = 0;  // two corners weld to the same vertex (ignored below)
  uint64_t zero_area_triangles = 0;        // three distinct but collinear corners (exact test)
  uint64_t edges = 0;                      // distinct undirected edges
  uint64_t border_edges = 0;               // used by exactly one triangle (open mesh)
  uint64_t non_manifold_edges = 0;         // used by more than two triangles
  uint64_t inconsistent_edges = 0;         // two triangles that traverse it the same way
  uint64_t components = 0;                 // edge-connected components
  // Components whose every edge is used by exactly two triangles in opposite directions.
  uint64_t closed_components = 0;
  // Closed components with negative signed volume (normals point inwards, e.g. a sealed room).
  uint64_t inward_closed_components = 0;
  bool self_intersections_checked = false;
  uint64_t self_intersecting_pairs = 0;  // pairs of triangles that intersect (when checked)
  // False when the self-intersection test had to give up (e.g. the soup could not be turned
  // into a polygon mesh); self_intersecting_pairs is then meaningless.
  bool self_intersections_complete = true;

  bool all_closed() const {
    return components > 0 && components == closed_components && degenerate_triangles == 0;
  }
};

// `positions` holds xyz per vertex, `indices` 3 per triangle.
MeshDiagnostics diagnose_mesh(const float* positions, size_t vertex_count, const uint32_t* indices,
                              size_t triangle_count, const MeshDiagnosticsOptions& options = {});
MeshDiagnostics diagnose_mesh(const Scene& scene, const MeshDiagnosticsOptions& options = {});

// Inside/outside queries against the closed components of a soup (as defined above) that
// have outward normals and no zero-area triangles; each such component gets its own AABB tree
// and CGAL::Side_of_triangle_mesh, so overlapping solids are handled. classify() is const and
// safe to call from several threads once constructed; it is deterministic.
//
// With SolidBuild::on_demand the constructor only welds the soup and finds the candidate
// components (closed, outward, no zero-area triangle); a candidate's CGAL mesh and tree are built
// the first time a query needs it (a point in its box; valid() builds the smallest candidates
// until one succeeds). The answers are the same as with every solid built up front; only the cost
// moves to the few solids that queries reach.
enum class SolidBuild { up_front, on_demand };

class ClosedMeshInsideTester {
 public:
  ClosedMeshInsideTester();  // no components: valid() is false
  explicit ClosedMeshInsideTester(const Scene& scene, SolidBuild build = SolidBuild::up_front);
  ClosedMeshInsideTester(const float* positions, size_t vertex_count, const uint32_t* indices,
                         size_t triangle_count, SolidBuild build = SolidBuild::up_front);
  ~ClosedMeshInsideTester();
  ClosedMeshInsideTester(ClosedMeshInsideTester&&) noexcept;
  ClosedMeshInsideTester& operator=(ClosedMeshInsideTester&&) noexcept;
  ClosedMeshInsideTester(const ClosedMeshInsideTester&) = delete;
  ClosedMeshInsideTester& operator=(const ClosedMeshInsideTester&) = delete;

  // True when at least one closed component could be used.
  bool valid() const;
  // Solids CGAL could build (on demand: builds every candidate first).
  size_t component_count() const;
  // Builds now (on demand: instead of at a first classify) every solid whose box, grown by `pad`
  // (x, y, z), holds one of the n points (xyz each); returns how many of them CGAL could build.
  size_t build_near(const float* points, size_t n, const float pad[3]) const;
  // +1: strictly inside some closed component; -1: outside all of them;
  // 0: on the surface of one (and inside none), a non-finite point, or !valid().
  int classify(const float p[3]) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gibake
