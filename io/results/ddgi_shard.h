// One shard of a split DDGI bake (`gibake bake --shard I/N`): what every probe of the shard's range
// holds once traced, before anything that reads other probes (the probe-feedback bounce passes) or
// all of them (atlases, counts, the file). `gibake merge` (bake/ddgi/shard_merge.h) finishes the bake
// from every shard. Written to and read from shard files by io/bakefile/bake_shard.h. Plain data.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/results/ddgi_result.h"

namespace gibake {

// Probes [begin, end) of shard `index` of `count`: contiguous index ranges (z-major slabs of the
// grid), as even as the probe count allows. The one rule the bake, the merge and the checks share.
struct ShardRange {
  uint32_t index = 0, count = 1;
  uint32_t begin = 0, end = 0;
};
inline ShardRange shard_range(uint32_t index, uint32_t count, uint32_t probes) {
  ShardRange r;
  r.index = index;
  r.count = count;
  r.begin = uint32_t(uint64_t(probes) * index / count);
  r.end = uint32_t(uint64_t(probes) * (index + 1) / count);
  return r;
}

struct DdgiShardProbe {
  float offset[3] = {0.f, 0.f, 0.f};
  bool inactive = false, enclosed = false, sky_only = false, moved = false;
  DdgiProbeStats stats;
  uint32_t integrated_rays = 0;  // rays pass 0 integrated (the bounce passes' weight)
  uint32_t bounce_hits = 0;      // hits of this probe in DdgiShard::bounce_hits
  uint64_t primary_rays = 0, shadow_rays = 0, bounce_rays = 0, relocation_rays = 0;
};

// Floats per kept bounce hit: direction xyz, distance, shading normal xyz, albedo rgb.
constexpr int kShardHitFloats = 10;
constexpr int kShardDepthTile = kDepthTexels + 2;

struct DdgiShard {
  ShardRange range;
  uint64_t input_hash = 0;     // of the complete bake
  uint64_t settings_hash = 0;  // of its canonical settings JSON
  DdgiVolumeDesc desc;         // the complete bake's grid
  int atlas_planes_per_row = 0;
  int irradiance_width = 0, irradiance_height = 0, depth_width = 0, depth_height = 0;
  bool probe_gather = false;  // bounce hits carried for the merge's bounce passes
  bool global = false;        // carries the bake's global volumes (LPV)
  uint32_t sh_format = 0, atlas_format = 0;  // FloatPrecision of the merged file
  // Closed-mesh check over the shard's probes (sums; `checked` is or-ed by the merge).
  bool closed_checked = false;
  uint32_t closed_inside = 0, closed_inside_but_active = 0, closed_inactive_outside = 0;
  std::vector<DdgiShardProbe> probes;  // range.end - range.begin
  std::vector<float> sh0;              // per probe: coefficients x RGB
  std::vector<float> irradiance;       // per probe: kIrradianceTexels^2 x RGB
  std::vector<float> depth_tiles;      // per probe: kShardDepthTile^2 x (mean, mean^2)
  std::vector<float> bounce_hits;      // kShardHitFloats per hit, probe after probe
  std::string metadata_json;           // the bake's metadata before the probe counts (tool, scene, settings)
};

}  // namespace gibake
