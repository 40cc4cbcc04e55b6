// The depth atlas at a coarser tile than the bake integrates (--depth-tile). Each file texel takes
// the moments (mean, mean^2) of the nearest of the 2x2 (or 4x4) bake texels it covers, the one
// with the smallest mean distance. Averaging the moments instead would mix a near occluder with
// the open space beside it into one wide distribution, and Chebyshev's test would then let light
// through walls; the nearest keeps the occluder sharp. What it costs, occluding points beyond that
// occluder in the sub-directions that were open, falls on one of the eight probes a point blends.
// The bake, its bounce passes and the probe filter work at the full tile; only the finished result
// is coarsened, so the one-go bake and the shard merge give the same bytes.
#pragma once

#include "io/results/ddgi_result.h"

namespace gibake {

// The tile sizes a file may hold: kDepthTexels divided by 1, 2 or 4.
bool valid_depth_tile(int interior);

// Replaces result.depth_atlas (tiles of result.depth_tile interior texels) by one of `interior`
// texels a tile side, same planes per row, borders rebuilt as the sampler expects. No-op when the
// atlas is empty or already that size. `interior` must divide result.depth_tile. Parallel over
// probes in the caller's task arena; deterministic (ties keep the first texel in row order).
void coarsen_depth_atlas(DdgiResult& result, int interior);

}  // namespace gibake
