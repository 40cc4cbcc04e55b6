// Paths ended at their first hit in a probe field, kept so that they can be ended in a field
// later (the fitted probes) without being traced again (trace_surface_irradiance's `keep`,
// bake/preview/ended_path_hits.h ends them). A path ended at its first hit brings the light before
// the hit (and the point's emitter sample), which no field changes, plus its weight times the
// field's irradiance at the hit: kept are that constant light, per point, and each hit's place,
// normal and weight.
#pragma once
#include <cstdint>
#include <vector>

#include "bake/trace/path_gather.h"
#include "kernels/vec.h"

namespace gibake {

struct EndedPathHits {
  // 24 bytes: the weight in half floats and the normal in 16-bit octahedral coordinates, far finer
  // than the probes' light changes (a shared read, CachedProbeField, bins normals by 6 degrees).
  struct Hit {
    float p[3];
    uint16_t weight[3];  // throughput x albedo at the hit, half floats
    uint16_t normal[2];  // shading normal, octahedral, 16-bit unorm
    uint8_t half = 0;    // the half of the point's paths it belongs to
  };
  struct Point {
    kernels::float3 base{};  // the light of the point's paths that the field does not give
    double base_half_lum[2] = {0.0, 0.0};
    uint32_t half_count[2] = {0, 0};  // paths in each half
    uint32_t rays = 0;                // 0: not kept (not traced)
    std::vector<Hit> hits;
  };
  bool complete = false;      // every traced point's paths were ended on the CPU and kept
  std::vector<Point> points;  // as trace_surface_irradiance's `out`
};
static_assert(sizeof(EndedPathHits::Hit) == 24, "a kept hit is 24 bytes");

// One point's paths, ended (EndedLight, not yet resolved), into `out`; halves[r] is path r's half
// of the point's paths.
void keep_ended_paths(const std::vector<EndedLight>& ended, const std::vector<uint8_t>& halves,
                      const uint32_t half_count[2], EndedPathHits::Point& out);

// What a kept hit adds to its point's light, read in `field` (EndedLight::resolve's term at the hit).
kernels::float3 kept_hit_light(const EndedPathHits::Hit& hit, const ProbeField& field);

}  // namespace gibake
