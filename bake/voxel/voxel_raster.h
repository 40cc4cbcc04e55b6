// Conservative triangle/voxel overlap (the separating-axis theorem) in voxel space, where voxel
// (i,j,k) is the closed unit box [i,i+1]x[j,j+1]x[k,k+1]. A voxel is reported when no separating
// axis exists among the 3 box axes, the triangle normal and the 9 edge x box-axis cross products
// (Akenine-Moeller 2001). For speed the 13 axes are evaluated in Schwarz & Seidel's (2010) form:
// the box axes by the triangle's voxel range, the normal by a column walk along the dominant
// normal axis (each column's overlapping voxels come from the plane equation), the 9 edge axes as
// 2D edge functions in the three axis-aligned projections. Boxes that only touch the triangle
// count as overlapping (closed sets), so a 1-voxel-thin wall leaves no gap.
// Degenerate triangles (collinear or coincident points) have no normal axis; they are walked
// slab by slab along their longest edge and tested against the 9 edge axes (a segment's SAT) and
// the box axes (their bounding box per slab), so they mark the voxels their points touch.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace gibake::voxel {

// Slack on every test, in voxel units: keeps boxes that touch the triangle within rounding.
constexpr double kOverlapEps = 1e-9;

struct TriangleRaster {
  double v[3][3];        // vertices in voxel space
  double n[3];           // cross(v1-v0, v2-v0)
  int32_t lo[3], hi[3];  // voxel index range (clamped to the grid), inclusive
  bool degenerate = false;
  bool empty = false;    // outside the grid or not finite
  // 2D edge functions per projection dropping axis a: en[a][e] . (p_u, p_w) + ed[a][e] >= 0.
  double en[3][3][2], ed[3][3], es[3][3];  // es: slack scaled to the edge's length
};

// Index range of voxels whose closed box [i, i+1] meets [lo, hi].
inline void voxel_range(double lo, double hi, int32_t dim, int32_t& out_lo, int32_t& out_hi) {
  const double a = std::ceil(lo - kOverlapEps) - 1.0, b = std::floor(hi + kOverlapEps);
  out_lo = static_cast<int32_t>(std::max(0.0, a));
  out_hi = static_cast<int32_t>(std::min(double(dim - 1), b));
}

// Degenerate when the third point lies within 1e-7 voxel of the line through the longest edge
// (|n| / longest edge is that distance); such triangles are walked as segments.
inline bool degenerate_triangle(const double n[3], double longest_edge2) {
  const double n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  return !(n2 > 1e-14 * longest_edge2);
}

// A triangle whose voxel range is one voxel overlaps exactly that voxel (it lies in the voxel's
// closed box, so no axis separates them): its index in `ijk`, and whether it is degenerate, without
// the edge set-up. False when the range spans more than one voxel or comes near the grid's edge.
inline bool single_voxel(const double v[3][3], const int32_t dims[3], int32_t ijk[3], bool& degenerate) {
  for (int k = 0; k < 3; ++k) {
    const double mn = std::min({v[0][k], v[1][k], v[2][k]}), mx = std::max({v[0][k], v[1][k], v[2][k]});
    if (!(mn >= 1.0 && mx <= double(dims[k] - 1))) return false;  // not near the grid's edge (no clamping)
    int32_t lo, hi;
    voxel_range(mn, mx, dims[k], lo, hi);
    if (lo != hi) return false;
    ijk[k] = lo;
  }
  const double e0[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
  const double e1[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
  const double n[3] = {e0[1] * e1[2] - e0[2] * e1[1], e0[2] * e1[0] - e0[0] * e1[2], e0[0] * e1[1] - e0[1] * e1[0]};
  double longest2 = 0.0;
  for (int e = 0; e < 3; ++e) {
    const double* p = v[e];
    const double* q = v[(e + 1) % 3];
    longest2 = std::max(longest2, (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                                      (q[2] - p[2]) * (q[2] - p[2]));
  }
  degenerate = degenerate_triangle(n, longest2);
  return true;
}

// Sets up triangle (a, b, c) given in voxel space for a grid of `dims` voxels.
inline TriangleRaster setup_triangle(const double a[3], const double b[3], const double c[3], const int32_t dims[3]) {
  TriangleRaster t;
  for (int k = 0; k < 3; ++k) {
    t.v[0][k] = a[k];
    t.v[1][k] = b[k];
    t.v[2][k] = c[k];
  }
  for (int k = 0; k < 3; ++k) {
    const double mn = std::min({a[k], b[k], c[k]}), mx = std::max({a[k], b[k], c[k]});
    if (!std::isfinite(mn) || !std::isfinite(mx)) {
      t.empty = true;
      return t;
    }
    voxel_range(mn, mx, dims[k], t.lo[k], t.hi[k]);
    if (t.lo[k] > t.hi[k]) t.empty = true;
  }
  const double e0[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e1[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  t.n[0] = e0[1] * e1[2] - e0[2] * e1[1];
  t.n[1] = e0[2] * e1[0] - e0[0] * e1[2];
  t.n[2] = e0[0] * e1[1] - e0[1] * e1[0];
  double longest2 = 0.0;
  for (int e = 0; e < 3; ++e) {
    const double* p = t.v[e];
    const double* q = t.v[(e + 1) % 3];
    const double d2 = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) + (q[2] - p[2]) * (q[2] - p[2]);
    longest2 = std::max(longest2, d2);
  }
  t.degenerate = degenerate_triangle(t.n, longest2);
  for (int ax = 0; ax < 3; ++ax) {
    const int u = (ax + 1) % 3, w = (ax + 2) % 3;
    const double s = t.degenerate ? 1.0 : (t.n[ax] >= 0.0 ? 1.0 : -1.0);
    for (int e = 0; e < 3; ++e) {
      const double* p = t.v[e];
      const double* q = t.v[(e + 1) % 3];
      const double nu = -(q[w] - p[w]) * s, nw = (q[u] - p[u]) * s;
      t.en[ax][e][0] = nu;
      t.en[ax][e][1] = nw;
      // Critical corner of the unit square: the one furthest along the edge normal.
      t.ed[ax][e] = -(nu * p[u] + nw * p[w]) + std::max(0.0, nu) + std::max(0.0, nw);
      t.es[ax][e] = kOverlapEps * (std::fabs(nu) + std::fabs(nw));
    }
  }
  return t;
}

// The projection dropping axis `ax` separates nothing: the unit square at (pu, pw) is on the
// inner side of all three edges (non-degenerate triangles).
inline bool edges_pass(const TriangleRaster& t, int ax, double pu, double pw) {
  for (int e = 0; e < 3; ++e)
    if (t.en[ax][e][0] * pu + t.en[ax][e][1] * pw + t.ed[ax][e] < -t.es[ax][e]) return false;
  return true;
}

// Separating-axis test of the 9 edge x box-axis axes for a degenerate triangle (a segment or a
// point): the triangle's and the unit box's projections must overlap on each axis.
inline bool degenerate_overlaps(const TriangleRaster& t, const double box_min[3]) {
  for (int e = 0; e < 3; ++e) {
    const double* p = t.v[e];
    const double* q = t.v[(e + 1) % 3];
    const double ed[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    for (int ax = 0; ax < 3; ++ax) {
      double axis[3] = {0, 0, 0};  // ed x unit(ax)
      const int u = (ax + 1) % 3, w = (ax + 2) % 3;
      axis[u] = ed[w];
      axis[w] = -ed[u];
      if (axis[u] == 0.0 && axis[w] == 0.0) continue;
      double tmin = 1e300, tmax = -1e300;
      for (int k = 0; k < 3; ++k) {
        const double d = axis[0] * t.v[k][0] + axis[1] * t.v[k][1] + axis[2] * t.v[k][2];
        tmin = std::min(tmin, d);
        tmax = std::max(tmax, d);
      }
      const double c = axis[0] * (box_min[0] + 0.5) + axis[1] * (box_min[1] + 0.5) + axis[2] * (box_min[2] + 0.5);
      const double r = 0.5 * (std::fabs(axis[0]) + std::fabs(axis[1]) + std::fabs(axis[2]));
      const double slack = kOverlapEps * (std::fabs(axis[u]) + std::fabs(axis[w]) + 1.0);
      if (tmin > c + r + slack || tmax < c - r - slack) return false;
    }
  }
  return true;
}

// Degenerate triangles: slabs along the longest axis of the bounding box; in each slab the
// bounding box of the three edges clipped to it gives the candidate voxels.
template <class F>
void walk_degenerate(const TriangleRaster& t, F&& f) {
  int d = 0;
  for (int k = 1; k < 3; ++k)
    if (t.hi[k] - t.lo[k] > t.hi[d] - t.lo[d]) d = k;
  for (int32_t s = t.lo[d]; s <= t.hi[d]; ++s) {
    double bmin[3] = {1e300, 1e300, 1e300}, bmax[3] = {-1e300, -1e300, -1e300};
    for (int e = 0; e < 3; ++e) {
      const double* p = t.v[e];
      const double* q = t.v[(e + 1) % 3];
      double t0 = 0.0, t1 = 1.0;
      const double dd = q[d] - p[d];
      if (dd != 0.0) {
        double a = (double(s) - kOverlapEps - p[d]) / dd, b = (double(s) + 1.0 + kOverlapEps - p[d]) / dd;
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        if (t0 > t1) continue;
      } else if (p[d] < double(s) - kOverlapEps || p[d] > double(s) + 1.0 + kOverlapEps) {
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        const double x0 = p[k] + t0 * (q[k] - p[k]), x1 = p[k] + t1 * (q[k] - p[k]);
        bmin[k] = std::min({bmin[k], x0, x1});
        bmax[k] = std::max({bmax[k], x0, x1});
      }
    }
    if (bmin[0] > bmax[0]) continue;
    int32_t lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      // Near-degenerate triangles deviate from their edges by < 1e-7 voxel.
      voxel_range(bmin[k] - 1e-6, bmax[k] + 1e-6, t.hi[k] + 1, lo[k], hi[k]);
      lo[k] = std::max(lo[k], t.lo[k]);
    }
    lo[d] = hi[d] = s;
    for (int32_t z = lo[2]; z <= hi[2]; ++z)
      for (int32_t y = lo[1]; y <= hi[1]; ++y)
        for (int32_t x = lo[0]; x <= hi[0]; ++x) {
          const double bm[3] = {double(x), double(y), double(z)};
          if (degenerate_overlaps(t, bm)) f(x, y, z);
        }
  }
}

// Calls f(x, y, z) once for every voxel of the grid the triangle overlaps.
template <class F>
void rasterize_triangle(const TriangleRaster& t, F&& f) {
  if (t.empty) return;
  if (t.degenerate) {
    walk_degenerate(t, f);
    return;
  }
  int w = 0;  // dominant normal axis: columns run along it
  for (int k = 1; k < 3; ++k)
    if (std::fabs(t.n[k]) > std::fabs(t.n[w])) w = k;
  const int u = (w + 1) % 3, v = (w + 2) % 3;
  const double D = t.n[0] * t.v[0][0] + t.n[1] * t.v[0][1] + t.n[2] * t.v[0][2];
  const double nu = t.n[u], nv = t.n[v], nw = t.n[w];
  int32_t p[3];
  for (int32_t pv = t.lo[v]; pv <= t.hi[v]; ++pv) {
    for (int32_t pu = t.lo[u]; pu <= t.hi[u]; ++pu) {
      // The projection along w (u, v plane) is the one dropping axis w.
      if (!edges_pass(t, w, pu, pv)) continue;
      const double s = nu * pu + nv * pv;
      const double s_lo = s + std::min(0.0, nu) + std::min(0.0, nv), s_hi = s + std::max(0.0, nu) + std::max(0.0, nv);
      const double t1 = (D - s_hi) / nw, t2 = (D - s_lo) / nw;
      const double tmin = std::min(t1, t2), tmax = std::max(t1, t2);
      const double slack = kOverlapEps * (std::fabs(nu) + std::fabs(nv) + std::fabs(nw)) / std::fabs(nw);
      const int32_t k0 = std::max<int32_t>(t.lo[w], static_cast<int32_t>(std::max(-1.0, std::ceil(tmin - 1.0 - slack))));
      const int32_t k1 = std::min<int32_t>(t.hi[w], static_cast<int32_t>(std::min(2.0e9, std::floor(tmax + slack))));
      p[u] = pu;
      p[v] = pv;
      for (int32_t k = k0; k <= k1; ++k) {
        p[w] = k;
        // Projections dropping u and dropping v: (v, w) and (w, u) coordinates.
        if (!edges_pass(t, u, p[(u + 1) % 3], p[(u + 2) % 3])) continue;
        if (!edges_pass(t, v, p[(v + 1) % 3], p[(v + 2) % 3])) continue;
        f(p[0], p[1], p[2]);
      }
    }
  }
}

}  // namespace gibake::voxel
