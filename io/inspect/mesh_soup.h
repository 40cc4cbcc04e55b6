// Internal to io/inspect: the welded triangle soup every diagnostic starts from, and the CGAL
// types the diagnostics and the inside tester share. Includes CGAL; not for use outside io/inspect.
#pragma once
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/inspect/mesh_diagnostics.h"

namespace gibake::mesh {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Polygon = std::array<std::size_t, 3>;
using Tri = std::array<uint32_t, 3>;

// Welded triangle soup: every position once, triangles reindexed; invalid triangles dropped.
struct Soup {
  std::vector<Vec3f> points;
  std::vector<Tri> tris;
};

inline Point to_point(const Vec3f& p) { return Point(p[0], p[1], p[2]); }
bool finite3(const float* p);

// Welds bit-identical positions (+0 and -0 alike); fills d.welded_vertices and d.invalid_triangles.
Soup weld(const float* positions, size_t vertex_count, const uint32_t* indices, size_t triangle_count,
          MeshDiagnostics& d);
// Drops triangles with repeated corners; flags (and counts) exactly collinear ones: one flag per
// kept triangle.
std::vector<uint8_t> remove_repeated(Soup& soup, MeshDiagnostics& d);

// Builds a triangle Surface_mesh from a soup, splitting non-manifold vertices and edges
// (orient_polygon_soup) where needed. Returns false when CGAL cannot make a mesh of it.
bool soup_to_mesh(std::vector<Point>& points, std::vector<Polygon>& polygons, Mesh& mesh);

}  // namespace gibake::mesh
