// One shard of a split DDGI bake (`gibake bake --shard I/N`): what every probe of the shard's range
// holds once traced, before anything that reads other probes (the probe-feedback bounce passes) or
// all of them (atlases, counts, the file). `gibake merge` (bake/ddgi/shard_merge.h) finishes the bake
// from every shard. Written to and read from shard files by io/bakefile/bake_shard.h. Plain data.
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "io/results/ddgi_result.h"

namespace gibake {

// A bake's probes fall into fixed blocks of kProbeBlock consecutive probes of a volume (the last
// block of a volume may hold fewer), numbered across the bake's volumes in the file's order. The
// adaptive ray budget is decided per block (bake/ddgi/trace_batches.h) and a shard owns whole blocks,
// so neither depends on how many shards there are: a shard traces its blocks exactly as the one-go
// bake does, and the merge of any shard count is that bake byte for byte.
constexpr uint32_t kProbeBlock = 512;
inline uint32_t probe_blocks(uint32_t probes) { return (probes + kProbeBlock - 1) / kProbeBlock; }

// Probes [begin, end) of a volume of `probes` probes that shard `index` of `count` owns: shard I of
// N owns blocks [floor(T I / N), floor(T (I + 1) / N)) of the bake's T blocks (the shards of a bake
// differ by at most one block); the volume's blocks are `first_block`.. of them. total_blocks 0:
// the volume's own (a bake of one volume). The one rule the bake, the merge and the checks share.
struct ShardRange {
  uint32_t index = 0, count = 1;
  uint32_t begin = 0, end = 0;
};
inline ShardRange shard_range(uint32_t index, uint32_t count, uint32_t probes, uint32_t first_block = 0,
                              uint32_t total_blocks = 0) {
  const uint64_t blocks = probe_blocks(probes);
  const uint64_t total = total_blocks ? total_blocks : first_block + blocks;
  auto probe_at = [&](uint64_t global_block) {
    const uint64_t b = std::min(blocks, global_block > first_block ? global_block - first_block : 0);
    return uint32_t(std::min<uint64_t>(probes, b * kProbeBlock));
  };
  ShardRange r;
  r.index = index;
  r.count = count;
  r.begin = probe_at(total * index / count);
  r.end = probe_at(total * (index + 1) / count);
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
  // Which of the bake's volumes this is (the file's order), of how many, where its blocks begin
  // among the bake's and how many blocks the bake has (shard_range).
  uint32_t volume = 0, volumes = 1, first_block = 0, total_blocks = 0;
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
