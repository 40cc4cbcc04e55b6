// A made-up DDGI volume of Sponza's default grid's shape for the sampler's benchmarks: 38 x 21 x 18
// probes 1 m apart, random SH, irradiance texels and depth moments of the bake's tile sizes (the
// same for every run: a fixed seed).
#pragma once
#include <random>

#include "io/results/ddgi_result.h"

namespace gibake {

inline DdgiResult sponza_shaped_volume(bool every_third_inactive) {
  DdgiResult r;
  r.desc.counts = {38, 21, 18};
  r.desc.sh_order = 2;
  r.desc.max_distance = 50.f;
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = 0.f;
    r.desc.spacing[a] = 1.f;
    r.desc.grid_max[a] = float(r.desc.counts[a] - 1);
  }
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const size_t n = size_t(r.desc.probe_count());
  for (size_t i = 0; i < n * 27; ++i) r.sh.push_back(i % 27 < 3 ? 1.f + 5.f * u(rng) : 0.2f * (u(rng) - 0.5f));
  for (size_t p = 0; p < n; ++p)
    r.states.push_back(every_third_inactive && p % 3 == 2 ? ProbeState::Inactive : ProbeState::Active);
  const int X = r.desc.counts[0], Y = r.desc.counts[1], Z = r.desc.counts[2];
  r.irradiance_width = X * Y * (kIrradianceTexels + 2);
  r.irradiance_height = Z * (kIrradianceTexels + 2);
  r.irradiance_atlas.resize(size_t(r.irradiance_width) * r.irradiance_height * 4);
  for (size_t i = 0; i < r.irradiance_atlas.size(); ++i) r.irradiance_atlas[i] = i % 4 == 3 ? 1.f : 100.f * u(rng);
  r.depth_width = X * Y * (kDepthTexels + 2);
  r.depth_height = Z * (kDepthTexels + 2);
  r.depth_atlas.resize(size_t(r.depth_width) * r.depth_height * 2);
  for (size_t i = 0; i < r.depth_atlas.size(); i += 2) {
    const float mean = 0.5f + 3.f * u(rng);
    r.depth_atlas[i] = mean;
    r.depth_atlas[i + 1] = mean * mean + 0.01f * u(rng);
  }
  return r;
}

}  // namespace gibake
