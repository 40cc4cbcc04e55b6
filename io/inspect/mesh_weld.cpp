// Welding, the first step of every mesh diagnostic: bit-identical positions become one vertex,
// triangles with repeated corners are dropped and collinear ones flagged (io/inspect/mesh_soup.h).
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "io/inspect/mesh_soup.h"

namespace gibake::mesh {
namespace {

struct PositionKey {
  uint32_t bits[3];
  bool operator==(const PositionKey& o) const {
    return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2];
  }
};

PositionKey key_of(const float* p) {
  PositionKey k;
  for (int i = 0; i < 3; ++i) {
    const float v = p[i] + 0.0f;  // -0 -> +0
    std::memcpy(&k.bits[i], &v, sizeof v);
  }
  return k;
}

}  // namespace

bool finite3(const float* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// Ids are handed out in the order triangles first reference a position (as a hash map keyed by
// position would), but positions are grouped by sorting compact (position, vertex) records: less
// memory than a hash map of every vertex, and faster on large scenes.
Soup weld(const float* positions, size_t vertex_count, const uint32_t* indices,
          size_t triangle_count, MeshDiagnostics& d) {
  struct Keyed {
    PositionKey key;
    uint32_t vertex;
  };
  std::vector<Keyed> keyed;
  keyed.reserve(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v)
    if (finite3(positions + v * 3)) keyed.push_back({key_of(positions + v * 3), uint32_t(v)});
  // Any total order groups equal positions (ids come from the triangle walk below, not from this
  // order); integers compare faster than memcmp, and the vertex makes every record distinct, so a
  // parallel sort (in the caller's arena) gives the one sorted sequence.
  tbb::parallel_sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
    if (a.key.bits[0] != b.key.bits[0]) return a.key.bits[0] < b.key.bits[0];
    if (a.key.bits[1] != b.key.bits[1]) return a.key.bits[1] < b.key.bits[1];
    if (a.key.bits[2] != b.key.bits[2]) return a.key.bits[2] < b.key.bits[2];
    return a.vertex < b.vertex;
  });
  std::vector<uint32_t> group(vertex_count, UINT32_MAX);  // equal positions share a group
  uint32_t groups = 0;
  for (size_t i = 0; i < keyed.size(); ++i) {
    if (i == 0 || !(keyed[i].key == keyed[i - 1].key)) ++groups;
    group[keyed[i].vertex] = groups - 1;
  }
  std::vector<Keyed>().swap(keyed);
  Soup soup;
  std::vector<uint32_t> id(groups, UINT32_MAX);
  soup.tris.reserve(triangle_count);
  for (size_t t = 0; t < triangle_count; ++t) {
    const uint32_t* c = indices + t * 3;
    bool ok = true;
    for (int i = 0; i < 3; ++i)
      ok = ok && c[i] < vertex_count && finite3(positions + size_t(c[i]) * 3);
    if (!ok) {
      ++d.invalid_triangles;
      continue;
    }
    Tri tri;
    for (int i = 0; i < 3; ++i) {
      uint32_t& w = id[group[c[i]]];
      if (w == UINT32_MAX) {
        const float* p = positions + size_t(c[i]) * 3;
        w = uint32_t(soup.points.size());
        soup.points.push_back({p[0], p[1], p[2]});
      }
      tri[i] = w;
    }
    soup.tris.push_back(tri);
  }
  d.welded_vertices = soup.points.size();
  return soup;
}

std::vector<uint8_t> remove_repeated(Soup& soup, MeshDiagnostics& d) {
  std::vector<uint8_t> zero_area;
  size_t kept = 0;
  for (const Tri& t : soup.tris) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      ++d.repeated_vertex_triangles;
      continue;
    }
    const bool flat = CGAL::collinear(to_point(soup.points[t[0]]), to_point(soup.points[t[1]]),
                                      to_point(soup.points[t[2]]));
    d.zero_area_triangles += flat ? 1 : 0;
    zero_area.push_back(flat ? 1 : 0);
    soup.tris[kept++] = t;
  }
  soup.tris.resize(kept);
  d.degenerate_triangles = d.repeated_vertex_triangles + d.zero_area_triangles;
  return zero_area;
}

}  // namespace gibake::mesh
