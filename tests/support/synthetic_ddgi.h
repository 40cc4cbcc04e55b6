// A synthetic whole-bake DDGI result for the writer's tests: `counts` probes over a 5 m box, SH from
// sin(), every probe active, and both atlases laid out as a bake would (`planes_per_row`, 0: one
// band) and filled with repeating ramps (irradiance up to 13,371, depth up to 5).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>

#include "io/results/ddgi_result.h"
#include "tests/support/ddgi_atlas_sizes.h"

namespace gibake::test {

inline DdgiResult synthetic_ddgi(std::array<int32_t, 3> counts, int planes_per_row = 0) {
  DdgiResult r;
  r.desc.counts = counts;
  r.desc.sh_order = 2;
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = 0.f;
    r.desc.grid_max[a] = 5.f;
    r.desc.spacing[a] = 5.f / float(r.desc.counts[a] - 1);
  }
  r.desc.max_distance = 20.f;
  r.atlas_planes_per_row = planes_per_row;
  const size_t n = size_t(r.desc.probe_count());
  r.sh.resize(n * 27);
  for (size_t i = 0; i < r.sh.size(); ++i) r.sh[i] = std::sin(float(i)) * 300.f;
  r.offsets.assign(n * 3, 0.01f);
  r.states.assign(n, ProbeState::Active);
  r.stats.assign(n, DdgiProbeStats{64, 0.02f, 0.4f, 0.f});
  size_ddgi_atlases(r);
  for (size_t i = 0; i < r.irradiance_atlas.size(); ++i) r.irradiance_atlas[i] = float(i % 977) * 13.7f;
  for (size_t i = 0; i < r.depth_atlas.size(); ++i) r.depth_atlas[i] = float(i % 501) * 0.01f;
  r.settings_json = R"({"rays":64})";
  return r;
}

}  // namespace gibake::test
