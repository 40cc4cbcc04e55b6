// The path-traced gather (--gather path): every probe ray that hits a surface continues as a
// path, so a probe converges to the incident radiance a path tracer computes at its position.
// At each vertex: emission (counted once, see below), next-event estimation towards the punctual
// lights (all, or one chosen at random) and towards one emissive triangle picked by power, both
// with shadow rays, then a cosine-weighted bounce. Emission found by a bounce ray and emission
// found by light sampling are combined with multiple importance sampling (power heuristic), so
// an emitter is never counted twice; the probe's own first ray takes emission at full weight
// (nothing samples it otherwise). Russian roulette after `roulette_depth` vertices. Thin glass
// (Material::transmission t) is crossed straight on with probability t, tinted, without using a
// bounce; shadow rays pass through it tinted (probe_rays.h transmittance; docs/ARCHITECTURE.md).
#pragma once
#include <cstdint>
#include <vector>

#include "bake/scene/emitters.h"
#include "bake/trace/probe_rays.h"

namespace gibake {

struct PathSetup {
  TraceSetup trace;                     // scene, sky, punctual lights, light choice, seed
  const EmitterTable* emitters = nullptr;
  int bounces = 4;                      // vertices after the first hit (0: direct light only)
  int roulette_depth = 3;               // vertices before Russian roulette may end a path
};

// The path tracer over `prepared` lit by `lights`, `sky` and the emissive triangles of `emitters`
// (which must outlive it): every light evaluated at each vertex, full-resolution textures unless a
// TextureLod is set afterwards, roulette after 3 vertices.
PathSetup make_path_setup(const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                          const EmitterTable& emitters, uint64_t seed, int bounces);

// Like trace_probe_rays (same records, same counters), but each record's radiance0 holds the
// whole path's radiance arriving along the probe ray. Deterministic: every random number is keyed
// by (seed, probe, pass, ray) and the vertex.
void trace_probe_paths(const PathSetup& setup, const kernels::float3& origin, uint32_t probe, uint32_t pass,
                       const float* dirs, uint32_t count, kernels::HitRecord* out, TraceCounters& counters,
                       std::vector<CapturedRay>* capture = nullptr);

// Radiance arriving at `origin` from direction -dir along the ray origin + t*dir (a camera ray of
// a reference render): the same path tracer, emission of the first hit at full weight. `key` seeds
// the path's random numbers (kernels::rng_hash of whatever identifies the sample).
kernels::float3 trace_radiance(const PathSetup& setup, const kernels::float3& origin, const kernels::float3& dir,
                               uint64_t key, TraceCounters& counters);

// Like trace_radiance, but only surfaces within tmax count: false (and `out` untouched) when the
// ray meets nothing before tmax. `back_face`: the hit is the back of a single-sided surface (its
// radiance is then 0). The voxel-GI bake looks into one voxel with it (bake/vxgi/).
bool trace_radiance_within(const PathSetup& setup, const kernels::float3& origin, const kernels::float3& dir, float tmax,
                           uint64_t key, TraceCounters& counters, kernels::float3& out, bool& back_face);

}  // namespace gibake
