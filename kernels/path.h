// Path-tracing math for the path-traced gather (bake/trace/path_gather.cpp): sampling a Lambertian
// bounce, picking a point on an emissive triangle, multiple importance sampling weights and
// Russian roulette. Plain data and pure functions so a compute-shader twin reads alike.
#pragma once
#include <cstdint>

#include "kernels/vec.h"

namespace gibake::kernels {

// Cosine-weighted direction about the unit normal n from two uniforms in [0,1).
// Its density is cos(theta)/pi per steradian.
float3 sample_cosine_hemisphere(const float3& n, float u1, float u2);

// Uniformly distributed barycentrics (u, v) of a triangle from two uniforms, in Embree's
// convention p = (1-u-v) v0 + u v1 + v v2 (area density 1/area).
void sample_triangle_barycentrics(float u1, float u2, float& u, float& v);

// Area density converted to solid angle as seen from a point at `distance`, where the light's
// surface normal makes cos_light with the direction back to that point (0 when grazing).
inline float area_to_solid_angle_pdf(float pdf_area, float distance, float cos_light) {
  return cos_light > 0.f ? pdf_area * distance * distance / cos_light : 0.f;
}

// Power heuristic (beta = 2) weight of a sample drawn from the technique with density `pdf_a`
// when `pdf_b` is the other technique's density for the same direction.
inline float power_heuristic(float pdf_a, float pdf_b) {
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0.f ? a / (a + b) : 0.f;
}

// Russian roulette survival probability for a path of throughput `t` at vertex `depth` (0 =
// first hit): 1 for the first `min_depth` vertices, then the throughput's largest channel,
// clamped to [0.05, 0.95] so paths neither stop at once nor run forever.
inline float roulette_survival(const float3& t, int depth, int min_depth) {
  if (depth < min_depth) return 1.f;
  const float m = t.x > t.y ? (t.x > t.z ? t.x : t.z) : (t.y > t.z ? t.y : t.z);
  return clampf(m, 0.05f, 0.95f);
}

// The ray index whose rng_hash(seed, probe, pass, .) keys a probe's emitter-sample shift: next to
// the rotation's 0xFFFFFFFF, beyond any ray.
constexpr uint32_t kProbeLightShiftRay = 0xFFFFFFFEu;

// The uniforms (pick, u, v) of a probe's emitter sample r of n: a randomly shifted rank-1 lattice,
// (r/n, frac(r a1), frac(r a2)) plus one shift per probe and pass (a1, a2: the R2 sequence's
// generators), so the n samples take the emitter triangles exactly in proportion to power and
// spread evenly over each, while each sample alone is uniform on [0,1)^3 (its density, hence the
// MIS weights, are those of independent sampling; the estimate stays unbiased). In 32-bit fixed
// point with wrap-around, so path.comp computes the same bits; `shift_key` =
// rng_hash(seed, probe, pass, kProbeLightShiftRay).
void probe_light_uniforms(uint64_t shift_key, uint32_t r, uint32_t n, float u[3]);

inline float max_component(const float3& v) { return v.x > v.y ? (v.x > v.z ? v.x : v.z) : (v.y > v.z ? v.y : v.z); }

}  // namespace gibake::kernels
