// Mesh diagnostics and the closed-mesh inside tester. CGAL stays in this file.
#include "io/inspect/mesh_diagnostics.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <mutex>
#include <numeric>
#include <unordered_map>
#include <utility>
#include <vector>

namespace gibake {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Polygon = std::array<std::size_t, 3>;

// ---------------------------------------------------------------- welding

using Tri = std::array<uint32_t, 3>;

// Welded triangle soup: every position once, triangles reindexed; invalid triangles dropped.
struct Soup {
  std::vector<Vec3f> points;
  std::vector<Tri> tris;
};

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

Point to_point(const Vec3f& p) { return Point(p[0], p[1], p[2]); }

// Drops triangles with repeated corners; flags (and counts) exactly collinear ones.
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

// ---------------------------------------------------------------- topology

struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// One use of an undirected edge by a triangle: key = (min << 32) | max.
struct EdgeUse {
  uint64_t key;
  uint32_t tri;
  bool forward;  // the triangle walks min -> max
  bool operator<(const EdgeUse& o) const { return key < o.key || (key == o.key && tri < o.tri); }
};

// Stable LSD radix sort by key, 16 bits a pass, passes whose digit never varies skipped. The uses
// come in triangle order, so the result is the (key, tri) order of EdgeUse::operator<.
void sort_by_key(std::vector<EdgeUse>& uses) {
  std::vector<EdgeUse> tmp(uses.size());
  std::vector<uint32_t> count(1u << 16);
  for (int shift = 0; shift < 64; shift += 16) {
    std::fill(count.begin(), count.end(), 0u);
    for (const EdgeUse& u : uses) ++count[(u.key >> shift) & 0xFFFF];
    if (count[(uses.front().key >> shift) & 0xFFFF] == uses.size()) continue;  // one digit: order stands
    uint32_t sum = 0;
    for (uint32_t& c : count) sum += std::exchange(c, sum);
    for (const EdgeUse& u : uses) tmp[count[(u.key >> shift) & 0xFFFF]++] = u;
    uses.swap(tmp);
  }
}

std::vector<EdgeUse> edge_uses(const Soup& soup) {
  std::vector<EdgeUse> uses;
  uses.reserve(soup.tris.size() * 3);
  for (uint32_t t = 0; t < soup.tris.size(); ++t) {
    for (int i = 0; i < 3; ++i) {
      const uint32_t a = soup.tris[t][i], b = soup.tris[t][(i + 1) % 3];
      const uint64_t lo = std::min(a, b), hi = std::max(a, b);
      uses.push_back({(lo << 32) | hi, t, a < b});
    }
  }
  if (!uses.empty()) sort_by_key(uses);
  return uses;
}

// Per-triangle component id (0..n-1) and per-component facts.
struct Topology {
  std::vector<uint32_t> component;
  std::vector<uint8_t> closed;
  std::vector<double> volume;  // signed, meaningful for closed components
  std::vector<uint8_t> has_zero_area;
};

// Scans the sorted edge uses: counts edge kinds, joins neighbours, marks open triangles.
void scan_edges(const std::vector<EdgeUse>& uses, UnionFind& uf, std::vector<uint8_t>& open,
                MeshDiagnostics& d) {
  for (size_t i = 0; i < uses.size();) {
    size_t j = i + 1;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    const size_t n = j - i;
    ++d.edges;
    bool bad = n != 2;
    if (n == 1) ++d.border_edges;
    if (n > 2) ++d.non_manifold_edges;
    if (n == 2 && uses[i].forward == uses[i + 1].forward) {
      ++d.inconsistent_edges;
      bad = true;
    }
    for (size_t k = i; k < j; ++k) {
      uf.unite(uses[i].tri, uses[k].tri);
      if (bad) open[uses[k].tri] = 1;
    }
    i = j;
  }
}

double signed_volume6(const Soup& soup, const Tri& t) {
  const Vec3f &a = soup.points[t[0]], &b = soup.points[t[1]], &c = soup.points[t[2]];
  const double cx = double(b[1]) * c[2] - double(b[2]) * c[1];
  const double cy = double(b[2]) * c[0] - double(b[0]) * c[2];
  const double cz = double(b[0]) * c[1] - double(b[1]) * c[0];
  return a[0] * cx + a[1] * cy + a[2] * cz;
}

Topology analyze(const Soup& soup, const std::vector<uint8_t>& zero_area, MeshDiagnostics& d) {
  const size_t n = soup.tris.size();
  UnionFind uf(n);
  std::vector<uint8_t> open(n, 0);
  scan_edges(edge_uses(soup), uf, open, d);

  Topology topo;
  topo.component.resize(n);
  std::vector<uint32_t> root_id(n, UINT32_MAX);
  for (uint32_t t = 0; t < n; ++t) {
    const uint32_t r = uf.find(t);
    if (root_id[r] == UINT32_MAX) {
      root_id[r] = uint32_t(topo.closed.size());
      topo.closed.push_back(1);
      topo.volume.push_back(0.0);
      topo.has_zero_area.push_back(0);
    }
    const uint32_t c = root_id[r];
    topo.component[t] = c;
    if (open[t]) topo.closed[c] = 0;
    if (zero_area[t]) topo.has_zero_area[c] = 1;
    topo.volume[c] += signed_volume6(soup, soup.tris[t]) / 6.0;
  }
  d.components = topo.closed.size();
  for (size_t c = 0; c < topo.closed.size(); ++c) {
    if (!topo.closed[c]) continue;
    ++d.closed_components;
    if (topo.volume[c] < 0.0) ++d.inward_closed_components;
  }
  return topo;
}

// ---------------------------------------------------------------- CGAL meshes

// Builds a triangle Surface_mesh from a soup, splitting non-manifold vertices and edges
// (orient_polygon_soup) where needed. Returns false when CGAL cannot make a mesh of it.
bool soup_to_mesh(std::vector<Point>& points, std::vector<Polygon>& polygons, Mesh& mesh) {
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    PMP::orient_polygon_soup(points, polygons);
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) return false;
  }
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return CGAL::is_triangle_mesh(mesh);
}

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

// ---------------------------------------------------------------- inside tester

namespace {

using Side = CGAL::Side_of_triangle_mesh<Mesh, Kernel>;
using Tree = Side::AABB_tree;

// One closed component with its own tree; never moved once built (the tree points into mesh).
struct Solid {
  Mesh mesh;
  std::unique_ptr<Tree> tree;
  std::unique_ptr<Side> side;
  CGAL::Bbox_3 box;
};

// Makes a Solid of the soup triangles `tris` (one component), or returns null when CGAL cannot.
std::unique_ptr<Solid> make_solid(const Soup& soup, const std::vector<uint32_t>& tris) {
  std::vector<Point> points;
  std::vector<Polygon> polygons;
  std::unordered_map<uint32_t, size_t> local;
  polygons.reserve(tris.size());
  for (uint32_t t : tris) {
    Polygon poly;
    for (int i = 0; i < 3; ++i) {
      const uint32_t v = soup.tris[t][i];
      auto it = local.emplace(v, points.size()).first;
      if (it->second == points.size()) points.push_back(to_point(soup.points[v]));
      poly[i] = it->second;
    }
    polygons.push_back(poly);
  }
  auto solid = std::make_unique<Solid>();
  if (!soup_to_mesh(points, polygons, solid->mesh) || !CGAL::is_closed(solid->mesh)) return {};
  solid->tree =
      std::make_unique<Tree>(faces(solid->mesh).first, faces(solid->mesh).second, solid->mesh);
  solid->tree->build();
  solid->box = solid->tree->bbox();
  solid->side = std::make_unique<Side>(*solid->tree);
  return solid;
}

// Triangles of each component that can be a solid: closed, outward (positive volume), and
// without zero-area triangles (CGAL's ray/triangle test requires non-degenerate triangles).
std::vector<std::vector<uint32_t>> solid_triangles(const Topology& topo) {
  std::vector<std::vector<uint32_t>> tris(topo.closed.size());
  for (uint32_t t = 0; t < topo.component.size(); ++t) {
    const uint32_t c = topo.component[t];
    if (topo.closed[c] && !topo.has_zero_area[c] && topo.volume[c] > 0.0) tris[c].push_back(t);
  }
  return tris;
}

// p within box b grown by pad on every side.
bool in_box(const CGAL::Bbox_3& b, const float p[3], const float pad[3] = nullptr) {
  const double px = pad ? pad[0] : 0.0, py = pad ? pad[1] : 0.0, pz = pad ? pad[2] : 0.0;
  return p[0] >= b.xmin() - px && p[0] <= b.xmax() + px && p[1] >= b.ymin() - py && p[1] <= b.ymax() + py &&
         p[2] >= b.zmin() - pz && p[2] <= b.zmax() + pz;
}

// A bounding-volume hierarchy over the solids' boxes, for point queries.
class BoxBvh {
 public:
  void build(std::vector<CGAL::Bbox_3> boxes) {
    boxes_ = std::move(boxes);
    order_.resize(boxes_.size());
    std::iota(order_.begin(), order_.end(), 0u);
    nodes_.clear();
    if (!boxes_.empty()) build_node(0, boxes_.size());
  }

  // Calls f(i) for each box i that contains p (each box grown by `pad` when given) until f
  // returns true; returns whether one did.
  template <class F>
  bool any_containing(const float p[3], F&& f, const float pad[3] = nullptr) const {
    if (nodes_.empty()) return false;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[stack[--top]];
      if (!in_box(n.box, p, pad)) continue;
      if (n.count == 0) {
        stack[top++] = n.left;
        stack[top++] = n.right;
        continue;
      }
      for (uint32_t k = n.first; k < n.first + n.count; ++k)
        if (in_box(boxes_[order_[k]], p, pad) && f(order_[k])) return true;
    }
    return false;
  }

 private:
  struct Node {
    CGAL::Bbox_3 box;
    uint32_t first = 0, count = 0, left = 0, right = 0;  // count 0: inner node
  };

  uint32_t build_node(size_t first, size_t last) {
    Node node;
    for (size_t k = first; k < last; ++k) node.box += boxes_[order_[k]];
    const uint32_t id = uint32_t(nodes_.size());
    nodes_.push_back(node);
    if (last - first <= 4) {
      nodes_[id].first = uint32_t(first);
      nodes_[id].count = uint32_t(last - first);
      return id;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (node.box.max(a) - node.box.min(a) > node.box.max(axis) - node.box.min(axis)) axis = a;
    const size_t mid = (first + last) / 2;
    std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + last,
                     [&](uint32_t a, uint32_t b) {
                       return boxes_[a].min(axis) + boxes_[a].max(axis) <
                              boxes_[b].min(axis) + boxes_[b].max(axis);
                     });
    const uint32_t left = build_node(first, mid);
    const uint32_t right = build_node(mid, last);
    nodes_[id].left = left;
    nodes_[id].right = right;
    return id;
  }

  std::vector<CGAL::Bbox_3> boxes_;
  std::vector<uint32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace

// A component that may be a solid; its Solid is made on first need (null when CGAL cannot).
struct Candidate {
  std::vector<uint32_t> tris;
  CGAL::Bbox_3 box;  // of its vertices: what the solid's tree would report
  std::once_flag once;
  std::unique_ptr<Solid> solid;
};

struct ClosedMeshInsideTester::Impl {
  Soup soup;  // kept while a candidate may still be built
  std::vector<std::unique_ptr<Candidate>> candidates;
  std::vector<uint32_t> by_size;  // candidate indices, fewest triangles first (ties: index)
  BoxBvh bvh;                     // over the candidates' boxes

  const Solid* solid(uint32_t i) const {
    Candidate& c = *candidates[i];
    std::call_once(c.once, [&] {
      try {
        c.solid = make_solid(soup, c.tris);
      } catch (const std::exception&) {
        // A component CGAL rejects is left out; the others still answer.
      }
    });
    return c.solid.get();
  }
};

ClosedMeshInsideTester::ClosedMeshInsideTester() : impl_(std::make_unique<Impl>()) {}

ClosedMeshInsideTester::ClosedMeshInsideTester(const Scene& scene, SolidBuild build)
    : ClosedMeshInsideTester(scene.positions.data(), scene.vertex_count(), scene.indices.data(),
                             scene.triangle_count(), build) {}

ClosedMeshInsideTester::ClosedMeshInsideTester(const float* positions, size_t vertex_count,
                                               const uint32_t* indices, size_t triangle_count,
                                               SolidBuild build)
    : impl_(std::make_unique<Impl>()) {
  MeshDiagnostics d;
  Impl& im = *impl_;
  im.soup = weld(positions, vertex_count, indices, triangle_count, d);
  const std::vector<uint8_t> zero_area = remove_repeated(im.soup, d);
  const Topology topo = analyze(im.soup, zero_area, d);
  std::vector<CGAL::Bbox_3> boxes;
  for (std::vector<uint32_t>& tris : solid_triangles(topo)) {
    if (tris.empty()) continue;
    auto c = std::make_unique<Candidate>();
    for (uint32_t t : tris)
      for (int k = 0; k < 3; ++k) c->box += to_point(im.soup.points[im.soup.tris[t][k]]).bbox();
    c->tris = std::move(tris);
    boxes.push_back(c->box);
    im.candidates.push_back(std::move(c));
  }
  im.by_size.resize(im.candidates.size());
  std::iota(im.by_size.begin(), im.by_size.end(), 0u);
  std::stable_sort(im.by_size.begin(), im.by_size.end(), [&](uint32_t a, uint32_t b) {
    return im.candidates[a]->tris.size() < im.candidates[b]->tris.size();
  });
  im.bvh.build(boxes);
  if (build == SolidBuild::up_front) component_count();
}

ClosedMeshInsideTester::~ClosedMeshInsideTester() = default;
ClosedMeshInsideTester::ClosedMeshInsideTester(ClosedMeshInsideTester&&) noexcept = default;
ClosedMeshInsideTester& ClosedMeshInsideTester::operator=(ClosedMeshInsideTester&&) noexcept =
    default;

bool ClosedMeshInsideTester::valid() const {
  if (!impl_) return false;
  for (uint32_t i : impl_->by_size)
    if (impl_->solid(i)) return true;
  return false;
}

size_t ClosedMeshInsideTester::component_count() const {
  size_t n = 0;
  if (impl_)
    for (uint32_t i = 0; i < impl_->candidates.size(); ++i) n += impl_->solid(i) != nullptr;
  return n;
}

size_t ClosedMeshInsideTester::build_near(const float* points, size_t n, const float pad[3]) const {
  if (!valid()) return 0;
  std::vector<uint8_t> near(impl_->candidates.size(), 0);
  for (size_t k = 0; k < n; ++k)
    if (finite3(&points[k * 3]))
      impl_->bvh.any_containing(&points[k * 3], [&](uint32_t i) {
        near[i] = 1;
        return false;  // keep looking: every box that holds the point
      }, pad);
  // Largest first, in parallel (in the caller's arena): one large solid bounds the wall time.
  std::vector<uint32_t> order;
  for (auto it = impl_->by_size.rbegin(); it != impl_->by_size.rend(); ++it)
    if (near[*it]) order.push_back(*it);
  std::atomic<size_t> built{0};
  tbb::parallel_for(size_t(0), order.size(), [&](size_t k) { built += impl_->solid(order[k]) != nullptr; },
                    tbb::simple_partitioner());
  return built;
}

int ClosedMeshInsideTester::classify(const float p[3]) const {
  if (!valid() || !finite3(p)) return 0;
  const Point q(p[0], p[1], p[2]);
  bool on_boundary = false;
  const bool inside = impl_->bvh.any_containing(p, [&](uint32_t i) {
    const Solid* solid = impl_->solid(i);
    if (!solid) return false;
    const CGAL::Bounded_side side = (*solid->side)(q);
    if (side == CGAL::ON_BOUNDARY) on_boundary = true;
    return side == CGAL::ON_BOUNDED_SIDE;
  });
  if (inside) return +1;
  return on_boundary ? 0 : -1;
}

}  // namespace gibake
