// Mesh diagnostics (io/inspect/mesh_diagnostics.h): welding (mesh_weld.cpp), edge topology
// (mesh_topology.cpp) and, on request, CGAL's self-intersection test. The closed-mesh inside
// tester is in closed_mesh_inside.cpp.
#include "io/inspect/mesh_diagnostics.h"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <exception>
#include <vector>

#include "io/inspect/mesh_soup.h"
#include "io/inspect/mesh_topology.h"

namespace gibake {
namespace mesh {

namespace PMP = CGAL::Polygon_mesh_processing;

bool soup_to_mesh(std::vector<Point>& points, std::vector<Polygon>& polygons, Mesh& mesh) {
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    PMP::orient_polygon_soup(points, polygons);
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) return false;
  }
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return CGAL::is_triangle_mesh(mesh);
}

}  // namespace mesh

namespace {

using namespace mesh;  // the soup and CGAL types every diagnostic shares (mesh_soup.h)

// Counts without storing: an output iterator that only increments.
struct CountingIterator {
  uint64_t* count;
  CountingIterator& operator*() { return *this; }
  CountingIterator& operator++() { return *this; }
  CountingIterator operator++(int) { return *this; }
  template <class T>
  CountingIterator& operator=(const T&) {
    ++*count;
    return *this;
  }
};

void check_self_intersections(const Soup& soup, const std::vector<uint8_t>& zero_area,
                              MeshDiagnostics& d) {
  d.self_intersections_checked = true;
  d.self_intersections_complete = false;
  std::vector<Point> points;
  points.reserve(soup.points.size());
  for (const Vec3f& p : soup.points) points.push_back(to_point(p));
  std::vector<Polygon> polygons;
  for (size_t t = 0; t < soup.tris.size(); ++t)
    if (!zero_area[t]) polygons.push_back({soup.tris[t][0], soup.tris[t][1], soup.tris[t][2]});
  try {
    PMP::repair_polygon_soup(points, polygons);
    Mesh mesh;
    if (!soup_to_mesh(points, polygons, mesh)) return;
    uint64_t pairs = 0;
    PMP::self_intersections(mesh, CountingIterator{&pairs});
    d.self_intersecting_pairs = pairs;
    d.self_intersections_complete = true;
  } catch (const std::exception&) {
    // CGAL precondition or numeric failure: leave the check marked incomplete.
  }
}

MeshDiagnostics diagnose_soup(const float* positions, size_t vertex_count, const uint32_t* indices,
                              size_t triangle_count, const MeshDiagnosticsOptions& options) {
  MeshDiagnostics d;
  d.triangles = triangle_count;
  d.input_vertices = vertex_count;
  Soup soup = weld(positions, vertex_count, indices, triangle_count, d);
  const std::vector<uint8_t> zero_area = remove_repeated(soup, d);
  analyze(soup, zero_area, d);
  if (options.check_self_intersections) check_self_intersections(soup, zero_area, d);
  return d;
}

}  // namespace

MeshDiagnostics diagnose_mesh(const float* positions, size_t vertex_count, const uint32_t* indices,
                              size_t triangle_count, const MeshDiagnosticsOptions& options) {
  return diagnose_soup(positions, vertex_count, indices, triangle_count, options);
}

MeshDiagnostics diagnose_mesh(const Scene& scene, const MeshDiagnosticsOptions& options) {
  return diagnose_soup(scene.positions.data(), scene.vertex_count(), scene.indices.data(),
                       scene.triangle_count(), options);
}

}  // namespace gibake
