// Independent answers for the voxelizer tests: an exact triangle/box intersection test written
// differently from the separating-axis code under test (vertex in box, triangle edge through box,
// box edge through triangle), and small scene helpers.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

#include "io/results/voxel_grid.h"
#include "io/scene.h"

namespace gibake::test {

using D3 = std::array<double, 3>;

inline D3 sub(const D3& a, const D3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot3(const D3& a, const D3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline D3 cross3(const D3& a, const D3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Segment p + t (q - p), t in [0,1], against the box [lo, hi] (slab clipping).
inline bool segment_hits_box(const D3& p, const D3& q, const D3& lo, const D3& hi) {
  double t0 = 0.0, t1 = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double d = q[a] - p[a];
    if (d == 0.0) {
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - p[a]) / d, tb = (hi[a] - p[a]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// Segment p-q against triangle (a, b, c), transversal crossings only (generic positions).
inline bool segment_hits_triangle(const D3& p, const D3& q, const D3& a, const D3& b, const D3& c) {
  const D3 n = cross3(sub(b, a), sub(c, a));
  const double dp = dot3(n, sub(p, a)), dq = dot3(n, sub(q, a));
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq) return false;
  const double t = dp / (dp - dq);
  const D3 x{p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2])};
  const double w0 = dot3(n, cross3(sub(b, a), sub(x, a))), w1 = dot3(n, cross3(sub(c, b), sub(x, b))),
               w2 = dot3(n, cross3(sub(a, c), sub(x, c)));
  return w0 >= 0 && w1 >= 0 && w2 >= 0;
}

// Whether triangle (a, b, c) meets the box [lo - grow, hi + grow] (grow may be negative).
inline bool triangle_meets_box(const D3& a, const D3& b, const D3& c, D3 lo, D3 hi, double grow) {
  for (int k = 0; k < 3; ++k) {
    lo[k] -= grow;
    hi[k] += grow;
  }
  const D3 v[3] = {a, b, c};
  for (const D3& p : v) {
    bool in = true;
    for (int k = 0; k < 3; ++k) in = in && p[k] >= lo[k] && p[k] <= hi[k];
    if (in) return true;
  }
  for (int e = 0; e < 3; ++e)
    if (segment_hits_box(v[e], v[(e + 1) % 3], lo, hi)) return true;
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i < 4; ++i) {
      D3 p, q;
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      p[axis] = lo[axis];
      q[axis] = hi[axis];
      p[u] = q[u] = (i & 1) ? hi[u] : lo[u];
      p[w] = q[w] = (i & 2) ? hi[w] : lo[w];
      if (segment_hits_triangle(p, q, a, b, c)) return true;
    }
  return false;
}

// Triangle t of the scene in the grid's voxel space.
inline void scene_triangle_voxels(const Scene& s, const VoxelGrid& g, size_t t, D3 out[3]) {
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a)
      out[k][a] = (double(s.positions[size_t(s.indices[t * 3 + k]) * 3 + a]) - g.origin[a]) / g.voxel_size;
}

inline size_t count_space(const VoxelGrid& g, VoxelSpace v) {
  return size_t(std::count(g.space.begin(), g.space.end(), uint8_t(v)));
}

inline VoxelSpace space_at(const VoxelGrid& g, float x, float y, float z) {
  const float p[3] = {x, y, z};
  return g.space_at(p);
}

// Whether a surface voxel holds world point (x,y,z), allowing `eps` voxels either way: points on
// voxel boundaries touch both sides, and float rounding may put them on either.
inline bool surface_touching(const VoxelGrid& g, float x, float y, float z, double eps = 1e-4) {
  const float p[3] = {x, y, z};
  int32_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const double f = (double(p[a]) - g.origin[a]) / g.voxel_size;
    lo[a] = std::max(0, int32_t(std::floor(f - eps)));
    hi[a] = std::min(g.dims[a] - 1, int32_t(std::floor(f + eps)));
  }
  for (int32_t k = lo[2]; k <= hi[2]; ++k)
    for (int32_t j = lo[1]; j <= hi[1]; ++j)
      for (int32_t i = lo[0]; i <= hi[0]; ++i)
        if (g.space[size_t(g.linear(i, j, k))] == uint8_t(VoxelSpace::Surface)) return true;
  return false;
}

}  // namespace gibake::test
