// For synthetic DDGI results (the writer's tests and bench): lays out and sizes the atlases from the
// probe counts and r.atlas_planes_per_row as a bake would, leaving the texel values to the caller.
#pragma once
#include "io/results/ddgi_result.h"
#include "kernels/octahedral.h"

namespace gibake::test {

// The layout of an atlas of `res`-texel tiles over r's probes.
inline kernels::AtlasLayout atlas_layout_of(const DdgiResult& r, int res) {
  kernels::AtlasLayout l;
  for (int a = 0; a < 3; ++a) l.counts[a] = r.desc.counts[a];
  l.res = res;
  l.planes_per_row = r.atlas_planes_per_row;
  return l;
}

inline void size_ddgi_atlases(DdgiResult& r) {
  const kernels::AtlasLayout irr = atlas_layout_of(r, kIrradianceTexels), depth = atlas_layout_of(r, kDepthTexels);
  r.irradiance_width = irr.width();
  r.irradiance_height = irr.height();
  r.depth_width = depth.width();
  r.depth_height = depth.height();
  r.irradiance_atlas.resize(size_t(irr.width()) * irr.height() * 4);
  r.depth_atlas.resize(size_t(depth.width()) * depth.height() * 2);
}

}  // namespace gibake::test
