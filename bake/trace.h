// Probe ray batches through Embree -> kernels::HitRecord (hit classification, surface
// attributes, direct light with one shadow ray per light, emission, sky for misses).
#pragma once
#include <cstdint>
#include <vector>

#include "bake/prepare.h"
#include "bake/ray_capture.h"
#include "bake/sky.h"
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
};

struct TraceCounters {
  uint64_t rays = 0;         // primary rays
  uint64_t shadow_rays = 0;
  uint32_t back_faces = 0;   // back-face hits on single-sided materials
  float nearest_front = -1.f;
};

// Traces `count` rays from `origin` along `dirs` (xyz triples) and writes `count` records.
// `capture` (optional) receives every ray traced, primary and shadow, in order.
// Deterministic: the only randomness (random light choice) is keyed by (seed, probe, pass, ray).
void trace_probe_rays(const TraceSetup& setup, const kernels::float3& origin, uint32_t probe, uint32_t pass,
                      const float* dirs, uint32_t count, kernels::HitRecord* out, TraceCounters& counters,
                      std::vector<CapturedRay>* capture = nullptr);

}  // namespace gibake
