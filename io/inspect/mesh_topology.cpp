// Edge topology of a welded soup (io/inspect/mesh_topology.h): edge uses sorted by key, then one
// scan that counts edge kinds and joins neighbouring triangles into components.
#include "io/inspect/mesh_topology.h"

#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

namespace gibake::mesh {
namespace {

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

}  // namespace

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

}  // namespace gibake::mesh
