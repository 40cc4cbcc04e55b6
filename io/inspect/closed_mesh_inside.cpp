// The closed-mesh inside tester (io/inspect/mesh_diagnostics.h): one CGAL AABB tree and
// Side_of_triangle_mesh a closed outward component, found through a BVH over their boxes.
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <memory>
#include <mutex>
#include <numeric>
#include <unordered_map>
#include <utility>
#include <vector>

#include "io/inspect/mesh_diagnostics.h"
#include "io/inspect/mesh_soup.h"
#include "io/inspect/mesh_topology.h"

namespace gibake {

using namespace mesh;  // the soup and CGAL types every diagnostic shares (mesh_soup.h)

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
