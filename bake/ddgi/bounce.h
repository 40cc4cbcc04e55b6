// Multi-bounce passes (DDGI's multi-bounce from the previous probe state): bounce k re-shades the
// hits that reflect light with the irradiance of pass k-1's probes (8-probe sampler with back-face
// and Chebyshev weights) and adds their radiance to each probe's pass-0 result. Exact by linearity:
// pass 0 already holds emission + direct + sky of every ray, and only the bouncing rays change from
// pass to pass.
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "io/context.h"
#include "kernels/ddgi_sample.h"

namespace gibake {

// What the bounce passes need of a hit that reflects light (front face, non-zero albedo).
struct BounceHit {
  float dir_t[4];   // ray direction, hit distance
  float normal[3];  // shading normal facing the ray
  float albedo[3];
};

struct BounceInputs {
  kernels::DdgiVolumeView volume;                             // grid, offsets, states, depth tiles (its sh is not used)
  const float* positions = nullptr;                           // probe_count*3 world positions the rays left from
  const std::vector<float>* sh0 = nullptr;                    // pass-0 SH, probe_count * coefficients * 3
  const std::vector<std::vector<BounceHit>>* hits = nullptr;  // per probe
  const uint32_t* probe_rays = nullptr;                       // rays each probe's pass 0 integrated
  const float* texel_dirs = nullptr;                          // kernels::oct_tile_directions(kIrradianceTexels)
  int sh_order = 2;
  int bounces = 0;
  float energy_conservation = 1.f;
};

struct BounceTimes {
  std::vector<std::pair<std::string, double>> stage_seconds;
};

// Runs passes 1..bounces. `sh` receives the last pass's SH (sh0 when bounces == 0);
// `irradiance` (probe_count * kIrradianceTexels^2 * 3, holding pass 0's texels) gets the last pass's bounce
// light added. Inactive probes get zero SH.
void run_bounce_passes(const BounceInputs& in, tbb::task_arena& arena, const Context& ctx, std::vector<float>& sh,
                       std::vector<float>& irradiance, BounceTimes& times);

}  // namespace gibake
