#include "bake/classify.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <numeric>

#include "io/inspect/mesh_diagnostics.h"

namespace gibake {

namespace {

// Vertex-connected components of the triangle soup after welding bit-identical positions (+0 and
// -0 alike), the way ClosedMeshInsideTester welds. Every edge-connected component the tester
// builds a solid from lies inside exactly one of these, so the tester built over the triangles
// of a subset of these components answers exactly like the full tester for every point that
// lies outside the bounding boxes of the components left out.
struct Components {
  std::vector<uint32_t> of_triangle;  // component per triangle (UINT32_MAX: invalid triangle)
  std::vector<std::array<float, 6>> box;  // finite-coordinate AABB per component (min xyz, max xyz)
  std::vector<uint32_t> triangles;        // triangle count per component
  std::vector<uint32_t> weld;             // welded vertex id per vertex
};

uint32_t find(std::vector<uint32_t>& parent, uint32_t a) {
  while (parent[a] != a) {
    parent[a] = parent[parent[a]];
    a = parent[a];
  }
  return a;
}

Components vertex_components(const Scene& scene) {
  const size_t vcount = scene.vertex_count(), tcount = scene.triangle_count();
  const float* pos = scene.positions.data();
  // Weld: sort (position bits, vertex id) records, give equal positions the same representative.
  struct Key {
    uint32_t k[3];
    uint32_t v;
  };
  std::vector<Key> keys(vcount);
  for (size_t v = 0; v < vcount; ++v) {
    keys[v].v = static_cast<uint32_t>(v);
    for (int a = 0; a < 3; ++a) {
      const float f = pos[v * 3 + a] + 0.f;  // -0 -> +0
      std::memcpy(&keys[v].k[a], &f, 4);
    }
  }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    if (a.k[0] != b.k[0]) return a.k[0] < b.k[0];
    if (a.k[1] != b.k[1]) return a.k[1] < b.k[1];
    if (a.k[2] != b.k[2]) return a.k[2] < b.k[2];
    return a.v < b.v;
  });
  std::vector<uint32_t> parent(vcount);
  std::iota(parent.begin(), parent.end(), 0u);
  std::vector<uint32_t> weld(vcount);
  uint32_t next_weld = 0;
  for (size_t i = 0; i < vcount; ++i) {
    if (i > 0 && keys[i - 1].k[0] == keys[i].k[0] && keys[i - 1].k[1] == keys[i].k[1] &&
        keys[i - 1].k[2] == keys[i].k[2]) {
      parent[keys[i].v] = find(parent, keys[i - 1].v);
      weld[keys[i].v] = next_weld - 1;
    } else {
      weld[keys[i].v] = next_weld++;
    }
  }
  std::vector<Key>().swap(keys);
  const uint32_t none = UINT32_MAX;
  for (size_t t = 0; t < tcount; ++t) {
    const uint32_t* idx = &scene.indices[t * 3];
    if (idx[0] >= vcount || idx[1] >= vcount || idx[2] >= vcount) continue;
    const uint32_t r0 = find(parent, idx[0]);
    for (int k = 1; k < 3; ++k) {
      const uint32_t rk = find(parent, idx[k]);
      if (rk != r0) parent[rk] = r0;
    }
  }
  Components c;
  c.weld = std::move(weld);
  c.of_triangle.assign(tcount, none);
  std::vector<uint32_t> id(vcount, none);
  for (size_t t = 0; t < tcount; ++t) {
    const uint32_t* idx = &scene.indices[t * 3];
    if (idx[0] >= vcount || idx[1] >= vcount || idx[2] >= vcount) continue;
    const uint32_t root = find(parent, idx[0]);
    if (id[root] == none) {
      id[root] = static_cast<uint32_t>(c.box.size());
      const float inf = INFINITY;
      c.box.push_back({inf, inf, inf, -inf, -inf, -inf});
      c.triangles.push_back(0);
    }
    const uint32_t comp = id[root];
    c.of_triangle[t] = comp;
    ++c.triangles[comp];
    auto& b = c.box[comp];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) {
        const float v = pos[size_t(idx[k]) * 3 + a];
        if (!std::isfinite(v)) continue;
        b[a] = std::min(b[a], v);
        b[3 + a] = std::max(b[3 + a], v);
      }
  }
  return c;
}

bool in_box(const std::array<float, 6>& b, const float* p) {
  return p[0] >= b[0] && p[0] <= b[3] && p[1] >= b[1] && p[1] <= b[4] && p[2] >= b[2] && p[2] <= b[5];
}

bool finite_triangle(const Scene& scene, const uint32_t* idx) {
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(scene.positions[size_t(idx[k]) * 3 + a])) return false;
  return true;
}

// The tester over the triangles of the components marked in `use`, less the triangles that cannot
// belong to a closed component: a triangle of a closed component has each of its three (welded)
// edges used by exactly two triangles, in opposite directions. Dropping the others changes no
// solid: every closed component consists of passing triangles only, and a closed surface made
// of passing triangles is edge-connected to nothing else, so it was a component of its own
// before. Triangles the tester ignores (invalid, non-finite, repeated vertex) are left out of
// the edge counts, as the tester leaves them out.
ClosedMeshInsideTester tester_for(const Scene& scene, const Components& comps, const std::vector<uint8_t>& use) {
  std::vector<uint32_t> tris;
  for (size_t t = 0; t < comps.of_triangle.size(); ++t) {
    const uint32_t c = comps.of_triangle[t];
    if (c == UINT32_MAX || !use[c]) continue;
    const uint32_t* idx = &scene.indices[t * 3];
    const uint32_t a = comps.weld[idx[0]], b = comps.weld[idx[1]], d = comps.weld[idx[2]];
    if (a == b || b == d || a == d || !finite_triangle(scene, idx)) continue;
    tris.push_back(static_cast<uint32_t>(t));
  }
  // Directed edges (from, to) of the kept triangles, sorted by undirected key.
  struct Edge {
    uint64_t key;  // min << 32 | max
    uint32_t tri;
    int8_t dir;    // +1: from < to
  };
  std::vector<Edge> edges;
  edges.reserve(tris.size() * 3);
  for (uint32_t t : tris) {
    const uint32_t* idx = &scene.indices[size_t(t) * 3];
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = comps.weld[idx[k]], v = comps.weld[idx[(k + 1) % 3]];
      const uint32_t lo = std::min(u, v), hi = std::max(u, v);
      edges.push_back({(uint64_t(lo) << 32) | hi, t, static_cast<int8_t>(u < v ? 1 : -1)});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.key < y.key; });
  std::vector<uint8_t> bad(scene.triangle_count(), 0);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    const bool ok = j - i == 2 && edges[i].dir != edges[i + 1].dir;
    if (!ok)
      for (size_t k = i; k < j; ++k) bad[edges[k].tri] = 1;
    i = j;
  }
  std::vector<uint8_t> keep(scene.triangle_count(), 0);
  for (uint32_t t : tris) keep[t] = !bad[t];
  std::vector<uint32_t> idx;
  for (uint32_t t : tris)
    if (keep[t]) idx.insert(idx.end(), &scene.indices[size_t(t) * 3], &scene.indices[size_t(t) * 3] + 3);
  if (idx.empty()) return ClosedMeshInsideTester();
  return ClosedMeshInsideTester(scene.positions.data(), scene.vertex_count(), idx.data(), idx.size() / 3);
}

}  // namespace

ClassifyReport classify_probes(const Scene& scene, const std::vector<float>& positions,
                               const std::vector<DdgiProbeStats>& stats, float backface_threshold,
                               bool use_cgal, std::vector<ProbeState>& states) {
  ClassifyReport report;
  const size_t n = stats.size();
  states.assign(n, ProbeState::Active);
  for (size_t i = 0; i < n; ++i)
    if (stats[i].backface_fraction > backface_threshold) states[i] = ProbeState::Inactive;
  if (!use_cgal || scene.triangle_count() == 0) return report;
  // A probe strictly inside a closed solid with outward normals sees that solid's back faces, so
  // only probes with some back-face hits are asked (the others count as "outside" for both).
  std::vector<size_t> asked;
  for (size_t i = 0; i < n; ++i)
    if (stats[i].backface_fraction > 0.f) asked.push_back(i);
  if (asked.empty()) return report;

  // CGAL is only built for the components whose box holds an asked probe ("near"); a probe in
  // no such box is outside every solid. The far components are only needed to learn whether any
  // solid exists at all (when no near one is a solid), and are then tried smallest first.
  const Components comps = vertex_components(scene);
  const size_t nc = comps.box.size();
  std::vector<uint8_t> near(nc, 0);
  std::vector<uint8_t> in_near_box(asked.size(), 0);
  for (size_t k = 0; k < asked.size(); ++k) {
    const float* p = &positions[asked[k] * 3];
    for (size_t c = 0; c < nc; ++c)
      if (in_box(comps.box[c], p)) {
        near[c] = 1;
        in_near_box[k] = 1;
      }
  }
  ClosedMeshInsideTester tester = tester_for(scene, comps, near);
  bool solids_exist = tester.valid();
  if (!solids_exist) {
    std::vector<uint32_t> far;
    for (size_t c = 0; c < nc; ++c)
      if (!near[c]) far.push_back(static_cast<uint32_t>(c));
    std::stable_sort(far.begin(), far.end(),
                     [&](uint32_t a, uint32_t b) { return comps.triangles[a] < comps.triangles[b]; });
    std::vector<uint8_t> one(nc, 0);
    for (uint32_t c : far) {
      one[c] = 1;
      if (tester_for(scene, comps, one).valid()) {
        solids_exist = true;
        break;
      }
      one[c] = 0;
    }
  }
  if (!solids_exist) return report;
  report.closed_mesh_checked = true;
  for (size_t k = 0; k < asked.size(); ++k) {
    const size_t i = asked[k];
    const int side = in_near_box[k] && tester.valid() ? tester.classify(&positions[i * 3]) : -1;
    if (side > 0) ++report.inside_by_cgal;
    if (side == 0) continue;
    const bool inside_rays = states[i] == ProbeState::Inactive;
    if (side > 0 && !inside_rays) ++report.disagreements;
    if (side < 0 && inside_rays) ++report.inactive_outside_closed;
  }
  return report;
}

bool probe_in_enclosed_space(const VoxelGrid& voxels, const float position[3]) {
  int32_t v[3];
  if (!voxels.voxel_of(position, v)) return false;
  const auto space = static_cast<VoxelSpace>(voxels.space[size_t(voxels.linear(v[0], v[1], v[2]))]);
  if (space != VoxelSpace::Surface) return space == VoxelSpace::Interior;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int32_t x = v[0] + dx, y = v[1] + dy, z = v[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x >= voxels.dims[0] || y >= voxels.dims[1] || z >= voxels.dims[2]) return false;
        if (static_cast<VoxelSpace>(voxels.space[size_t(voxels.linear(x, y, z))]) == VoxelSpace::Exterior) return false;
      }
  return true;
}

}  // namespace gibake
