// Per-surface-voxel channels from the voxel's fragments (see voxel_internal.h).
//
// Each fragment (a triangle overlapping the voxel) is clipped to the voxel's box (Sutherland-
// Hodgman, 6 planes). The clipped polygon's area weights the fragment, and its centroid is where
// the material is sampled (`surface_sample`: base colour with textures and vertex colours,
// emission, interpolated normal) and where direct light is gathered. The centroid of the clipped
// part, not the point closest to the voxel centre: it is the mean position of the piece of surface
// the voxel holds, so for textures that vary linearly over it, one sample there equals the
// area-weighted mean over the piece; the closest point to the centre can sit on the piece's edge
// (or off it, for a triangle that only grazes the voxel) and then samples texels the voxel barely holds.
//
// Channels (weights w = clipped area; a voxel whose fragments all have zero area, i.e. only
// touch it, weighs them equally):
//   coverage = min(1, sum(area * |n_geo[dominant axis]| * opacity)) / face area: the fragments'
//              area projected onto their dominant axis, so a flat wall crossing the voxel gives 1;
//              opacity is 0 where a MASK (or BLEND, as MASK) material's alpha at the centroid is
//              below its cutoff, else 1;
//   albedo, emission, direct = w-weighted means; normal = normalized w-weighted sum of shading
//              normals; aniso[+x,-x,+y,-y,+z,-z] = w-weighted mean of max(0, +-n_axis) (as in VXGI:
//              the share of the voxel's surface facing each direction, |n| split by sign).
//   direct   = irradiance (lux) on the fragment's lit side: sum over lights of E * max(0, n.l) with
//              an Embree shadow ray from the centroid; single-sided materials are lit from their
//              front (counter-clockwise) side only, double-sided ones from the side facing the light.
#include <algorithm>
#include <cmath>

#include "bake/scene/material.h"
#include "bake/scene/prepare.h"
#include "bake/voxel/voxel_internal.h"

namespace gibake::voxel {
using kernels::float3;

namespace {

constexpr int kMaxPoly = 12;
constexpr double kClipGrow = 1e-7;  // voxel units: keeps boxes the overlap test found (within its slack)

struct Poly {
  double p[kMaxPoly][3];
  int n = 0;
};

// Keeps the part of `in` with sign * (x[axis] - bound) >= 0.
void clip_plane(const Poly& in, int axis, double bound, double sign, Poly& out) {
  out.n = 0;
  for (int i = 0; i < in.n; ++i) {
    const double* a = in.p[i];
    const double* b = in.p[(i + 1) % in.n];
    const double da = sign * (a[axis] - bound), db = sign * (b[axis] - bound);
    if (da >= 0.0 && out.n < kMaxPoly) std::copy(a, a + 3, out.p[out.n++]);
    if ((da >= 0.0) != (db >= 0.0) && out.n < kMaxPoly) {
      const double t = da / (da - db);
      for (int k = 0; k < 3; ++k) out.p[out.n][k] = a[k] + t * (b[k] - a[k]);
      ++out.n;
    }
  }
}

// Triangle clipped to voxel box `ijk` (grown by kClipGrow): area and centroid in voxel units.
bool clip_to_voxel(const double v[3][3], const int32_t ijk[3], double& area, double c[3]) {
  Poly a, b;
  a.n = 3;
  for (int k = 0; k < 3; ++k) std::copy(v[k], v[k] + 3, a.p[k]);
  for (int axis = 0; axis < 3; ++axis) {
    clip_plane(a, axis, double(ijk[axis]) - kClipGrow, 1.0, b);
    clip_plane(b, axis, double(ijk[axis]) + 1.0 + kClipGrow, -1.0, a);
  }
  if (a.n == 0) return false;
  double sx = 0, sy = 0, sz = 0, wsum = 0, ax = 0, ay = 0, az = 0;
  for (int i = 1; i + 1 < a.n; ++i) {
    const double* p0 = a.p[0];
    const double* p1 = a.p[i];
    const double* p2 = a.p[i + 1];
    const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
    const double w = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    ax += cx;
    ay += cy;
    az += cz;
    wsum += w;
    sx += w * (p0[0] + p1[0] + p2[0]) / 3.0;
    sy += w * (p0[1] + p1[1] + p2[1]) / 3.0;
    sz += w * (p0[2] + p1[2] + p2[2]) / 3.0;
  }
  area = 0.5 * std::sqrt(ax * ax + ay * ay + az * az);
  if (wsum > 1e-300) {
    c[0] = sx / wsum;
    c[1] = sy / wsum;
    c[2] = sz / wsum;
  } else {  // a segment or a point: mean of the vertices
    c[0] = c[1] = c[2] = 0.0;
    for (int i = 0; i < a.n; ++i)
      for (int k = 0; k < 3; ++k) c[k] += a.p[i][k] / a.n;
  }
  return true;
}

// Embree-style barycentrics (p = (1-u-v) v0 + u v1 + v v2) of p, clamped into the triangle;
// (1/3, 1/3) for a degenerate triangle.
void barycentrics(const double v[3][3], const double p[3], float& u, float& w) {
  double e0[3], e1[3], d[3];
  for (int k = 0; k < 3; ++k) {
    e0[k] = v[1][k] - v[0][k];
    e1[k] = v[2][k] - v[0][k];
    d[k] = p[k] - v[0][k];
  }
  auto dot = [](const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(d, e0), d21 = dot(d, e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 1e-14 * d00 * d11) || !(den > 0.0)) {
    u = w = 1.f / 3.f;
    return;
  }
  double bu = (d11 * d20 - d01 * d21) / den, bv = (d00 * d21 - d01 * d20) / den;
  bu = std::max(0.0, bu);
  bv = std::max(0.0, bv);
  if (bu + bv > 1.0) {
    const double s = bu + bv;
    bu /= s;
    bv /= s;
  }
  u = float(bu);
  w = float(bv);
}

// Irradiance (lux) at world point p with shading normal n (unit); shadow rays leave from p moved
// by `offset` along the geometric normal ng turned to the light's side.
float3 direct_irradiance(const ChannelInputs& in, const float3& p, const float3& n, const float3& ng, bool two_sided,
                         float offset, uint64_t& rays) {
  float3 e{0.f, 0.f, 0.f};
  for (const kernels::ShadeLight& light : *in.lights) {
    kernels::LightSample ls;
    if (!kernels::sample_light(light, p, ls)) continue;
    float cos_t = kernels::dot(n, ls.to_light);
    float side = 1.f;
    if (cos_t < 0.f) {
      if (!two_sided) continue;
      cos_t = -cos_t;
      side = -1.f;
    }
    if (!(cos_t > 0.f)) continue;
    float3 ngs = ng * side;
    if (kernels::dot(ngs, ls.to_light) < 0.f) ngs = -ngs;  // shading and geometric normals disagree
    const float3 org = p + ngs * offset;
    ++rays;
    const float tfar = std::isfinite(ls.distance) ? std::max(0.f, ls.distance - offset) : INFINITY;
    if (in.prepared->occluded(org, ls.to_light, 0.f, tfar)) continue;
    e += ls.illuminance * cos_t;
  }
  return e;
}

// Per-voxel sums: area-weighted (a, aniso) and unweighted (u, uaniso, for voxels whose fragments
// all have zero area). a/u hold albedo, emission, direct, normal: 3 values each.
struct Accum {
  double w = 0.0, n = 0.0;  // area sum, fragment count
  double cov = 0.0;
  double a[12] = {};
  double aniso[6] = {};
  double u[12] = {};
  double uaniso[6] = {};

  void add(double area, const float3& albedo, const float3& emission, const float3& direct, const float3& normal) {
    const float vals[12] = {albedo.x, albedo.y, albedo.z, emission.x, emission.y, emission.z,
                            direct.x, direct.y, direct.z, normal.x,   normal.y,   normal.z};
    for (int k = 0; k < 12; ++k) {
      a[k] += area * vals[k];
      u[k] += vals[k];
    }
    const float nn[3] = {normal.x, normal.y, normal.z};
    for (int k = 0; k < 3; ++k) {
      const int f = nn[k] >= 0.f ? 2 * k : 2 * k + 1;
      aniso[f] += area * std::fabs(nn[k]);
      uaniso[f] += std::fabs(nn[k]);
    }
    w += area;
    n += 1.0;
  }
};

}  // namespace

uint64_t fill_channels(const ChannelInputs& in, const Fragment* frags, size_t count, SurfaceVoxel& out) {
  const Scene& scene = *in.scene;
  const VoxelGrid& g = *in.grid;
  const bool lit = in.lights && !in.lights->empty() && in.prepared;
  Accum acc;
  uint64_t rays = 0;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t tri = frags[i].tri;
    double v[3][3], c[3], area = 0.0;
    triangle_in_voxels(scene, g, tri, v);
    if (!clip_to_voxel(v, out.ijk, area, c))
      for (int k = 0; k < 3; ++k) c[k] = (v[0][k] + v[1][k] + v[2][k]) / 3.0;
    float bu, bv;
    barycentrics(v, c, bu, bv);
    const SurfaceSample ss = surface_sample(scene, tri, bu, bv);
    const double e0[3] = {v[1][0] - v[0][0], v[1][1] - v[0][1], v[1][2] - v[0][2]};
    const double e1[3] = {v[2][0] - v[0][0], v[2][1] - v[0][1], v[2][2] - v[0][2]};
    float3 ng = kernels::normalize(float3{float(e0[1] * e1[2] - e0[2] * e1[1]), float(e0[2] * e1[0] - e0[0] * e1[2]),
                                          float(e0[0] * e1[1] - e0[1] * e1[0])});
    float3 ns = kernels::normalize(ss.normal);
    if (kernels::dot(ns, ns) == 0.f) ns = ng;
    if (kernels::dot(ng, ng) == 0.f) ng = ns;
    const Material& m = triangle_material(scene, tri);
    const float cutoff = alpha_cutoff_of(m, in.blend_cutoff);
    const double opacity = cutoff >= 0.f && surface_alpha(scene, tri, bu, bv) < cutoff ? 0.0 : 1.0;
    const double dom = std::max({std::fabs(ng.x), std::fabs(ng.y), std::fabs(ng.z)});
    acc.cov += area * dom * opacity;
    float3 direct{0.f, 0.f, 0.f};
    if (lit) {
      const float3 p{float(g.origin[0] + c[0] * g.voxel_size), float(g.origin[1] + c[1] * g.voxel_size),
                     float(g.origin[2] + c[2] * g.voxel_size)};
      const float extent = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.f});
      const float offset = std::max(1e-3f * g.voxel_size, 1e-5f * extent);
      direct = direct_irradiance(in, p, ns, ng, m.double_sided, offset, rays);
    }
    acc.add(area, ss.albedo, ss.emission, direct, ns);
  }
  const bool weighted = acc.w > 1e-12;
  const double* s = weighted ? acc.a : acc.u;
  const double* sa = weighted ? acc.aniso : acc.uaniso;
  const double inv = 1.0 / (weighted ? acc.w : acc.n);
  for (int k = 0; k < 3; ++k) {
    out.albedo[k] = float(s[k] * inv);
    out.emission[k] = float(s[3 + k] * inv);
    out.direct[k] = float(s[6 + k] * inv);
  }
  const double nl = std::sqrt(s[9] * s[9] + s[10] * s[10] + s[11] * s[11]);
  for (int k = 0; k < 3; ++k) out.normal[k] = nl > 1e-12 ? float(s[9 + k] / nl) : 0.f;
  for (int f = 0; f < 6; ++f) out.aniso[f] = float(sa[f] * inv);
  out.coverage = float(std::min(1.0, acc.cov));
  return rays;
}

}  // namespace gibake::voxel
