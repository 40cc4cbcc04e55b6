// DDGI settings for tests that place their probes by hand: `counts` probes per axis from `lo` to
// `hi` (the grid's first and last probe), `rays` rays a probe; every other setting at its default.
#pragma once
#include <array>
#include <cstdint>

#include "bake/ddgi/ddgi.h"

namespace gibake::test {

inline DdgiSettings probe_grid(const Vec3f& lo, const Vec3f& hi, const std::array<int32_t, 3>& counts, uint32_t rays) {
  DdgiSettings s;
  s.grid.explicit_bounds = true;
  s.grid.grid_min = lo;
  s.grid.grid_max = hi;
  s.grid.counts = counts;
  s.rays = rays;
  return s;
}

}  // namespace gibake::test
