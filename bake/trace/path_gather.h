// The path-traced gather (--gather path): every probe ray that hits a surface continues as a
// path, so a probe converges to the incident radiance a path tracer computes at its position.
// At each vertex: emission (counted once, see below), next-event estimation towards the punctual
// lights (all, or one chosen at random) and towards one emissive triangle picked by power, both
// with shadow rays, then a cosine-weighted bounce. Emission found by a bounce ray and emission
// found by light sampling are combined with multiple importance sampling (power heuristic), so
// an emitter is never counted twice. The probe itself samples the emitters too when the caller asks
// for its light samples (the DDGI trace does whenever the scene has emissive triangles): each probe
// ray r of a batch of N is paired with one point on an emissive triangle picked by power, seen
// from the probe through a shadow ray, and the two are combined by MIS with the power heuristic:
// the probe ray (density 1/(4 pi): each ray of the rotated Fibonacci set is uniform on the sphere)
// takes emission it hits with weight p_ray^2 / (p_ray^2 + p_light^2), the light sample
// L_e w_light / p_light (one sample of each per pair, so no counts enter the weights). The N
// samples' uniforms are a randomly shifted lattice (kernels::probe_light_uniforms): each alone is
// uniform, together they take the triangles in proportion to power and cover each evenly. A small
// bright lamp then reaches every probe through N light samples instead of the few rays that
// happen to hit it; without emitters nothing changes (docs/ARCHITECTURE.md).
// Russian roulette after `roulette_depth` vertices. Thin glass
// (Material::transmission t) is crossed straight on with probability t, tinted, without using a
// bounce; shadow rays pass through it tinted (probe_rays.h transmittance; docs/ARCHITECTURE.md).
#pragma once
#include <cstdint>
#include <vector>

#include "bake/scene/emitters.h"
#include "bake/trace/probe_rays.h"
#include "kernels/integrate.h"

namespace gibake {

namespace loader {
class BakeFile;
}  // namespace loader

// Light that a path reads from baked probes instead of tracing on past its first hit. Probes hold
// what rays find (the sky, emissive surfaces, every bounce) but not the punctual lights, which no
// ray meets: a path that ends at its first hit takes that hit's emission, the punctual lights
// there, and albedo / pi times this irradiance. A first hit on an emitter is not read from probes
// (those beside it see it at close range, far brighter than its surface is lit): that path goes on.
struct ProbeField {
  virtual ~ProbeField() = default;
  // Irradiance (lux) at surface point p with shading normal n.
  virtual kernels::float3 irradiance(const kernels::float3& p, const kernels::float3& n) const = 0;
  // The bake file whose every volume BakeFile::sample_ddgi blends with default options to give
  // irradiance(), when that is all it is: a device can then read the same probes itself.
  virtual const loader::BakeFile* file() const { return nullptr; }
};

struct PathSetup {
  TraceSetup trace;                     // scene, sky, punctual lights, light choice, seed
  const EmitterTable* emitters = nullptr;
  const ProbeField* probe_field = nullptr;  // set: paths end at their first hit, lit from there by it
  int bounces = 4;                      // vertices after the first hit (0: direct light only)
  int roulette_depth = 3;               // vertices before Russian roulette may end a path
};

// The path length of a yardstick (`preview --reference`, the reconstruction check): never the
// bake's own. Past the roulette depth a path survives a vertex with probability at most 0.95
// (kernels::roulette_survival), so roulette ends every path long before this bound, which
// truncates no light a measurement could see and only guarantees an end in a closed white box.
constexpr int kReferenceBounces = 1024;

// The path tracer over `prepared` lit by `lights`, `sky` and the emissive triangles of `emitters`
// (which must outlive it): every light evaluated at each vertex, full-resolution textures unless a
// TextureLod is set afterwards, roulette after 3 vertices.
PathSetup make_path_setup(const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                          const EmitterTable& emitters, uint64_t seed, int bounces);

// Like trace_probe_rays (same records, same counters), but each record's radiance0 holds the
// whole path's radiance arriving along the probe ray. Deterministic: every random number is keyed
// by (seed, probe, pass, ray) and the vertex.
// `lights` (optional, `count` entries): ray r's paired emitter sample from the probe, as an
// integration sample (direction to the emitter point; radiance L_e w_light / (4 pi p_light), zero
// when the sample is blocked or missed, depth unused) so that kernels::integrate_radiance over the
// rays and these together, normalised by the ray count, is the MIS estimate; the rays' emission is
// then MIS-weighted. Null, or a scene without emitters: the rays take emission at full weight.
void trace_probe_paths(const PathSetup& setup, const kernels::float3& origin, uint32_t probe, uint32_t pass,
                       const float* dirs, uint32_t count, kernels::HitRecord* out, TraceCounters& counters,
                       std::vector<CapturedRay>* capture = nullptr, kernels::RaySample* lights = nullptr);

// Radiance arriving at `origin` from direction -dir along the ray origin + t*dir (a camera ray of
// a reference render): the same path tracer, emission of the first hit at full weight. `key` seeds
// the path's random numbers (kernels::rng_hash of whatever identifies the sample).
kernels::float3 trace_radiance(const PathSetup& setup, const kernels::float3& origin, const kernels::float3& dir,
                               uint64_t key, TraceCounters& counters);

// Radiance reaching a surface point (shading normal n, geometric ng, `origin` offset off it) along
// `dir`, a direction drawn cosine-weighted about n, paired with one emitter sample at the point from
// the uniforms `u` (a point on an emissive triangle picked by power): the ray's emission and the
// emitter sample weighted by MIS (power heuristic, one sample of each), so that pi / N times the
// sum over N pairs estimates the irradiance. A small bright lamp then reaches the point through
// every pair instead of the few rays that happen to hit it. `traced` false (the ray below the
// geometric surface): the emitter sample alone. Without emitters, trace_radiance (or nothing when
// not traced). The sky, sampled or not, is found by the rays alone.
// `probe_lit` (with setup.probe_field): the path is not ended at its first hit but traced whole,
// and what it would have brought ended there is written to `probe_lit` (both estimates from one
// path, for a caller that weighs one against the other).
kernels::float3 trace_surface_radiance(const PathSetup& setup, const kernels::float3& origin, const kernels::float3& n,
                                       const kernels::float3& ng, const kernels::float3& dir, bool traced,
                                       const float u[3], uint64_t key, TraceCounters& counters,
                                       kernels::float3* probe_lit = nullptr);

// The light a path would have brought ended at its first hit, with the probe field still to be
// read: a caller reads the fields of many paths together after tracing them (their probes' tiles
// then stay in cache between reads, rather than being evicted by the traversal in between).
// resolve() gives the bytes trace_surface_radiance's `probe_lit` gives.
struct EndedLight {
  kernels::float3 base{};    // the path's light before the field (all of it when !at_hit)
  kernels::float3 weight{};  // throughput x albedo at the hit
  kernels::float3 p{}, n{};  // the hit and its shading normal
  kernels::float3 after{};   // the point's emitter sample, added last
  bool at_hit = false, has_after = false;
  kernels::float3 resolve(const ProbeField* field) const;
};
// trace_surface_radiance with `ended` (not null) in place of probe_lit.
kernels::float3 trace_surface_radiance_ended(const PathSetup& setup, const kernels::float3& origin,
                                             const kernels::float3& n, const kernels::float3& ng,
                                             const kernels::float3& dir, bool traced, const float u[3], uint64_t key,
                                             TraceCounters& counters, EndedLight& ended);

// Like trace_radiance, but only surfaces within tmax count: false (and `out` untouched) when the
// ray meets nothing before tmax. `back_face`: the hit is the back of a single-sided surface (its
// radiance is then 0). The voxel-GI bake looks into one voxel with it (bake/vxgi/).
bool trace_radiance_within(const PathSetup& setup, const kernels::float3& origin, const kernels::float3& dir, float tmax,
                           uint64_t key, TraceCounters& counters, kernels::float3& out, bool& back_face);

}  // namespace gibake
