// Probe ray batches through Embree -> kernels::HitRecord (hit classification, surface
// attributes, direct light with one shadow ray per light, emission, sky for misses).
#pragma once
#include <cstdint>
#include <vector>

#include "bake/scene/prepare.h"
#include "bake/scene/sky.h"
#include "bake/scene/texture_lod.h"
#include "bake/trace/ray_capture.h"
#include "kernels/shade.h"

namespace gibake {

struct TraceSetup {
  const PreparedScene* prepared = nullptr;
  const Sky* sky = nullptr;
  const kernels::ShadeLight* lights = nullptr;
  int light_count = 0;
  bool random_light = false;  // one uniformly chosen light per hit, scaled by light_count
  bool shade = true;          // false: geometry only (relocation pass)
  uint64_t seed = 0;
  float shadow_bias = 1e-4f;  // relative to the hit point's magnitude (min 1e-4 m)
  // Texture level of detail (bake/scene/texture_lod.h): each probe ray's footprint widens by
  // `cone_spread` radians (a share of its spacing sqrt(4 pi / rays), bake/ddgi/ddgi.cpp); null:
  // full-resolution textures.
  const TextureLod* lod = nullptr;
  float cone_spread = 0.f;
};

struct TraceCounters {
  uint64_t rays = 0;         // primary rays
  uint64_t shadow_rays = 0;
  uint64_t bounce_rays = 0;  // path continuation rays (path-traced gather)
  uint32_t back_faces = 0;   // back-face hits on single-sided materials
  float nearest_front = -1.f;
};

// Reflected radiance at a surface point from the punctual lights (every light, or one chosen with
// uniform `u_choice` when setup.random_light), each with a shadow ray from `shadow_org`, plus
// `emission`: emission + albedo/pi * sum visibility * E * max(0, n.l). `ng` is the geometric normal
// on the side the light must reach.
kernels::float3 shade_punctual(const TraceSetup& setup, const kernels::float3& shadow_org, const kernels::float3& n,
                               const kernels::float3& ng, const kernels::float3& albedo,
                               const kernels::float3& emission, float u_choice, TraceCounters& counters,
                               std::vector<CapturedRay>* capture);

// shade_punctual in two steps, so that the shadow rays can be cast before the surface's albedo is
// read (their traversal hides the albedo texels' loads; bake/scene/material.h PendingSurface):
// cast_punctual samples the lights and casts the rays, shade_cast counts and records them and
// weighs them by the albedo. Together they give shade_punctual's value, counts and captured rays,
// bit for bit; rays cast for a black albedo are neither counted nor recorded.
struct PunctualRays {
  static constexpr int kStackLights = 16;  // on the stack up to this many lights (no heap per vertex)
  kernels::LightSample stack_samples[kStackLights];
  float stack_visibility[kStackLights];
  std::vector<kernels::LightSample> heap_samples;
  std::vector<float> heap_visibility;
  int count = 0;      // rays cast
  float scale = 1.f;  // the light count when one light was chosen at random
  kernels::LightSample* samples() { return heap_samples.empty() ? stack_samples : heap_samples.data(); }
  const kernels::LightSample* samples() const { return heap_samples.empty() ? stack_samples : heap_samples.data(); }
  float* visibility() { return heap_visibility.empty() ? stack_visibility : heap_visibility.data(); }
  const float* visibility() const { return heap_visibility.empty() ? stack_visibility : heap_visibility.data(); }
};
void cast_punctual(const TraceSetup& setup, const kernels::float3& shadow_org, const kernels::float3& n,
                   const kernels::float3& ng, float u_choice, PunctualRays& out);
kernels::float3 shade_cast(const TraceSetup& setup, const PunctualRays& rays, const kernels::float3& shadow_org,
                           const kernels::float3& n, const kernels::float3& albedo, const kernels::float3& emission,
                           TraceCounters& counters, std::vector<CapturedRay>* capture);

// Light let through along org + t*dir, t in [0, tfar] (a shadow ray): 0 when an opaque surface is
// in the way, else the product over the thin transmissive surfaces crossed (Material::transmission
// > 0) of transmission x base colour (level-0 textures), either side. Without transmissive materials
// in the scene it is one any-hit ray (1 or 0). At most kMaxGlassCrossings surfaces are crossed.
constexpr int kMaxGlassCrossings = 16;
kernels::float3 transmittance(const TraceSetup& setup, const kernels::float3& org, const kernels::float3& dir, float tfar);

// Offset origin for rays leaving a surface point p on the side of the unit normal ng.
kernels::float3 offset_origin(const TraceSetup& setup, const kernels::float3& p, const kernels::float3& ng);

// Traces `count` rays from `origin` along `dirs` (xyz triples) and writes `count` records.
// `capture` (optional) receives every ray traced, primary and shadow, in order.
// Deterministic: the only randomness (random light choice) is keyed by (seed, probe, pass, ray).
void trace_probe_rays(const TraceSetup& setup, const kernels::float3& origin, uint32_t probe, uint32_t pass,
                      const float* dirs, uint32_t count, kernels::HitRecord* out, TraceCounters& counters,
                      std::vector<CapturedRay>* capture = nullptr);

}  // namespace gibake
