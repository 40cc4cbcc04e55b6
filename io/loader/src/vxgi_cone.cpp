// The CPU cone tracer over voxel-GI volumes (VXGI's ConeTrace / ConeTraceDiffuse /
// ConeTraceSpecular, front-to-back compositing), so an engine can check its shader against it.
//
// Differences from Wicked Engine's VXGI, each with its reason (docs/ARCHITECTURE.md, "Voxel GI"):
//  * face weights are dir.x^2, dir.y^2, dir.z^2 (sum 1): VXGI's |dir| weights sum to up to
//    sqrt(3), giving diagonal cones up to sqrt(3) times the light of axis-aligned ones;
//  * a sample's opacity is corrected for the step it stands for, a' = 1 - (1 - a)^(step / voxel),
//    colour scaled by a'/a (premultiplied radiance keeps its ratio), instead of VXGI's linear
//    `sam *= step / voxelSize`, which exceeds alpha 1 for long steps;
//  * the diffuse set is 6 cones of 60 degrees in the normal's frame, weighted by the cosine-weighted
//    solid angle each represents (pi/4 for the 30-degree cap around n, 3pi/20 for each fifth of the
//    ring from 30 to 90 degrees): sum pi, so no empirical factor (Wicked's 0.5) is needed. VXGI's
//    16 fixed world directions give 5 to 10 cones per hemisphere depending on n, so irradiance
//    changes with the normal's orientation relative to the world axes.
#include <algorithm>
#include <cmath>

#include "gibake/loader.hpp"

namespace gibake::loader {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr uint32_t kMaxSteps = 4096;

Vec3 madd(const Vec3& a, const Vec3& b, float s) { return {a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s}; }
float dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 normalized(const Vec3& a) {
  const float l = std::sqrt(dot(a, a));
  return l > 0.f ? Vec3{a[0] / l, a[1] / l, a[2] / l} : Vec3{0.f, 0.f, 1.f};
}

// Orthonormal tangent frame of a unit vector (Duff et al. 2017, branchless).
void frame(const Vec3& n, Vec3& t, Vec3& b) {
  const float sign = std::copysign(1.f, n[2]);
  const float a = -1.f / (sign + n[2]);
  const float c = n[0] * n[1] * a;
  t = {1.f + sign * n[0] * n[0] * a, sign * c, -sign * n[0]};
  b = {c, sign + n[1] * n[1] * a, -n[1]};
}

bool overlaps(const VxgiVolume& v, const Vec3& q, float radius) {
  const gibake_vxgi_volume& d = v.desc();
  for (int a = 0; a < 3; ++a) {
    const float lo = d.grid_min[a] - radius, hi = d.grid_min[a] + float(d.dims[a]) * d.voxel_size + radius;
    if (!(q[size_t(a)] >= lo && q[size_t(a)] <= hi)) return false;
  }
  return true;
}

// Distance from q to the nearest face of the volume's box, inwards (negative outside).
float inner_margin(const VxgiVolume& v, const Vec3& q) {
  const gibake_vxgi_volume& d = v.desc();
  float m = 1e30f;
  for (int a = 0; a < 3; ++a) {
    const float lo = d.grid_min[a], hi = lo + float(d.dims[a]) * d.voxel_size;
    m = std::min(m, std::min(q[size_t(a)] - lo, hi - q[size_t(a)]));
  }
  return m;
}

// What clipmap k gives for a footprint at q, with the blend towards k + 1 near k's border.
// What volume v gives a cone: the precomputed slice when asked for and stored, else the faces.
Rgba cone_sample(const VxgiVolume& v, uint32_t slice, float lod, const Vec3& dir, const Vec3& q) {
  return slice && slice < v.faces() ? v.sample_slice(lod, slice, dir, q) : v.sample_cone(lod, dir, q);
}

Rgba clipmap_sample(const VxgiClipmaps& c, size_t k, uint32_t slice, float footprint, const Vec3& dir, const Vec3& q,
                    float& voxel) {
  const VxgiVolume& v = c[k];
  const float vk = v.desc().voxel_size;
  const float lod = std::log2(footprint / vk);
  Rgba s = cone_sample(v, slice, lod, dir, q);
  voxel = vk * std::exp2(std::min(std::max(lod, 0.f), float(v.levels() - 1)));
  if (k + 1 < c.count) {
    const float w = 1.f - std::min(std::max((inner_margin(v, q) - 0.5f * footprint) / (2.f * voxel), 0.f), 1.f);
    if (w > 0.f) {
      const Rgba s1 = cone_sample(c[k + 1], slice, std::log2(footprint / c[k + 1].desc().voxel_size), dir, q);
      for (int i = 0; i < 4; ++i) s[size_t(i)] += w * (s1[size_t(i)] - s[size_t(i)]);
    }
  }
  return s;
}

// Free distance at q from the finest clipmap containing it (the coarsest otherwise: clamp to
// edge); 0 when that clipmap has no SDF. Finer clipmaps' distances stop at their border.
float clipmap_sdf(const VxgiClipmaps& c, size_t from, const Vec3& q, bool& has) {
  size_t j = from;
  while (j + 1 < c.count && !c[j].contains(q)) ++j;
  has = c[j].has_sdf();
  return has ? c[j].sdf(q) : 0.f;
}

}  // namespace

ConeResult cone_trace(const VxgiClipmaps& c, const Vec3& p, const Vec3& n, const Vec3& dir_in, float aperture,
                      const ConeOptions& o, uint32_t slice) {
  ConeResult r;
  if (c.count == 0) return r;
  const Vec3 dir = normalized(dir_in);
  size_t base = 0;  // the finest clipmap holding p: the cone's own scale
  while (base + 1 < c.count && !c[base].contains(p)) ++base;
  const VxgiVolume& outer = c[c.count - 1];
  const float v0 = c[base].desc().voxel_size;
  const float coef = 2.f * std::tan(std::min(std::max(aperture, 1e-4f), 3.1f) * 0.5f);
  const Vec3 start = madd(p, n, o.start_offset * v0);
  const float max_dist = o.max_distance > 0.f ? o.max_distance : 1e30f;
  float dist = v0;
  while (r.alpha < o.alpha_stop && r.steps < kMaxSteps) {
    const Vec3 q = madd(start, dir, dist);
    if (dist > max_dist) break;
    const float diameter = std::max(v0, coef * dist);
    // The cone's footprint left the outermost volume: what is beyond is the sky. Samples whose
    // centre is outside but whose footprint still overlaps the volume read its border (clamp to
    // edge), so a wide cone does not step over a wall that lies at the volume's border.
    if (!overlaps(outer, q, 0.5f * diameter)) {
      for (int k = 0; k < 3; ++k) r.radiance[size_t(k)] += (1.f - r.alpha) * outer.desc().sky[k];
      break;
    }
    ++r.steps;
    // The texel sampled may not reach back to the cone's start: a trilinear sample reads texels up
    // to one texel size away, so texels are kept within self_occlusion_limit x the distance
    // travelled (else a cone leaving a floor reads the floor's own coarse texel, dark and opaque).
    float footprint = diameter;
    if (o.self_occlusion_limit > 0.f) footprint = std::min(footprint, std::max(v0, o.self_occlusion_limit * dist));
    size_t k = base;  // the finest clipmap whose box holds the footprint
    while (k + 1 < c.count && inner_margin(c[k], q) < 0.5f * footprint) ++k;
    float voxel = 0.f;
    const Rgba s = clipmap_sample(c, k, slice, footprint, dir, q, voxel);
    const float step = std::max(0.5f * v0, o.step_scale * footprint);
    const float a = std::min(std::max(s[3], 0.f), 1.f);
    const float ratio = step / voxel;
    const float a_step = a >= 1.f ? 1.f : 1.f - std::pow(1.f - a, ratio);
    const float scale = a > 1e-6f ? a_step / a : ratio;
    for (int i = 0; i < 3; ++i) r.radiance[size_t(i)] += (1.f - r.alpha) * std::max(s[size_t(i)], 0.f) * scale;
    r.alpha += (1.f - r.alpha) * a_step;
    float advance = step;
    if (o.use_sdf) {
      bool has = false;
      const float free = clipmap_sdf(c, base, q, has);
      if (has) advance = std::max(advance, free - 0.5f * diameter - footprint);
    }
    dist += advance;
  }
  r.alpha = std::min(r.alpha, 1.f);
  return r;
}

void diffuse_cones(const Vec3& n_in, Vec3 dirs[6], float weights[6]) {
  const Vec3 n = normalized(n_in);
  Vec3 t, b;
  frame(n, t, b);
  dirs[0] = n;
  weights[0] = kPi / 4.f;  // cosine-weighted solid angle of the cap within 30 degrees: pi sin^2(30)
  const float c = 0.5f, s = 0.8660254f;  // 60 degrees from n
  for (int k = 0; k < 5; ++k) {
    const float phi = 2.f * kPi * float(k) / 5.f;
    const float cp = std::cos(phi), sp = std::sin(phi);
    for (int a = 0; a < 3; ++a) dirs[k + 1][size_t(a)] = c * n[size_t(a)] + s * (cp * t[size_t(a)] + sp * b[size_t(a)]);
    weights[k + 1] = 3.f * kPi / 20.f;  // (pi - pi/4) / 5
  }
}

// ConeOptions::seed_cones is the deprecated name of precomputed_cones: callers that still set it
// get the same cones.
static bool wants_precomputed_cones(const ConeOptions& o) { return o.precomputed_cones || o.seed_cones; }

Rgb cone_trace_diffuse(const VxgiClipmaps& v, const Vec3& p, const Vec3& n, const ConeOptions& o) {
  const Vec3 nn = normalized(n);
  Rgb e{0.f, 0.f, 0.f};
  if (wants_precomputed_cones(o)) {
    // The 16 precomputed cone directions (VXGI's ConeTraceDiffuse): those above the surface,
    // cos-weighted and normalised by the sum of the cosines (times pi: irradiance of the
    // cos-weighted mean radiance).
    const std::array<Vec3, 16>& dirs = precomputed_cone_directions();
    float sum = 0.f;
    for (uint32_t i = 0; i < 16; ++i) {
      const float cos_t = dot(nn, dirs[i]);
      if (cos_t <= 0.f) continue;
      const ConeResult r = cone_trace(v, p, nn, dirs[i], 0.872665f, o, 6 + i);
      for (int c = 0; c < 3; ++c) e[size_t(c)] += cos_t * r.radiance[size_t(c)];
      sum += cos_t;
    }
    for (float& c : e) c = sum > 0.f ? c * kPi / sum : 0.f;
  } else if (o.diffuse_cones > 6) {
    // N cones on a cosine-weighted Fibonacci spiral of the hemisphere, equal weights pi/N, each
    // the apex angle of a cap of solid angle 2 pi / N.
    const uint32_t count = o.diffuse_cones;
    Vec3 t, b;
    frame(nn, t, b);
    const float aperture = 2.f * std::acos(1.f - 1.f / float(count));
    for (uint32_t k = 0; k < count; ++k) {
      const float u = (float(k) + 0.5f) / float(count);
      const float sin_t = std::sqrt(u), cos_t = std::sqrt(1.f - u);
      const float phi = float(k) * 2.39996323f;
      Vec3 d;
      for (int a = 0; a < 3; ++a)
        d[size_t(a)] = cos_t * nn[size_t(a)] + sin_t * (std::cos(phi) * t[size_t(a)] + std::sin(phi) * b[size_t(a)]);
      const ConeResult r = cone_trace(v, p, nn, d, aperture, o);
      for (int c = 0; c < 3; ++c) e[size_t(c)] += kPi / float(count) * r.radiance[size_t(c)];
    }
  } else {
    Vec3 dirs[6];
    float weights[6];
    diffuse_cones(n, dirs, weights);
    for (int k = 0; k < 6; ++k) {
      const ConeResult r = cone_trace(v, p, nn, dirs[k], kPi / 3.f, o);
      for (int c = 0; c < 3; ++c) e[size_t(c)] += weights[k] * r.radiance[size_t(c)];
    }
  }
  if (o.calibrated)
    for (float& c : e) c *= v[0].desc().diffuse_scale;
  return e;
}

ConeResult cone_trace_specular(const VxgiClipmaps& v, const Vec3& p, const Vec3& n_in, const Vec3& to_eye,
                               float roughness, const ConeOptions& o) {
  const Vec3 n = normalized(n_in), e = normalized(to_eye);
  const float ne = dot(n, e);
  const Vec3 r = {2.f * ne * n[0] - e[0], 2.f * ne * n[1] - e[1], 2.f * ne * n[2] - e[2]};
  return cone_trace(v, p, n, r, std::max(0.05f, roughness * kPi * 0.5f), o);
}

}  // namespace gibake::loader
