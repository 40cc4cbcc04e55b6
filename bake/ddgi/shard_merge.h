// `gibake merge part_*.gibake --out probes.gibake`: checks that shard files (bake/ddgi/shard_bake.h)
// belong together and finishes the bake from them: the probe-feedback bounce passes over every
// probe, the atlases, states, counts and the file, byte-identical to the same bake made in one go.
// The LPV cascades come from the shard that baked them (the global one), copied byte for byte.
#pragma once
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/run/backend.h"
#include "io/context.h"
#include "io/results/ddgi_shard.h"
#include "io/status.h"

namespace gibake {

struct MergeOptions {
  std::vector<std::string> parts;  // shard files, any order
  std::string out;
  // Only for a probe-feedback bake made on Vulkan, whose bounce passes must run on the same kind of
  // device: default (Auto) the device its settings name.
  BackendSettings backend{Backend::Auto, "", false, true};
};

struct MergeReport {
  DdgiReport ddgi;
  DdgiResult result;  // the grid only (desc): the arrays are released once written
  uint32_t shards = 0;
  bool lpv = false;  // LPV cascades copied from the global shard
  std::vector<std::pair<std::string, double>> stage_seconds;
};

// Every shard of one bake exactly once: the same input hash, settings hash, grid and storage
// formats; indices 0..N-1 each once. Names the offending part (InvalidInput), or the missing shard.
// `order[i]`: the position in `shards` of shard i.
Status check_shard_set(const std::vector<std::string>& paths, const std::vector<DdgiShard>& shards,
                       std::vector<size_t>& order);

// Finishes the bake from the ordered, checked shards (their probe data is released as it is used).
// `settings_json`: the bake's settings object (DDGI keys; "lpv" ignored).
Status merge_ddgi_shards(std::vector<DdgiShard>& shards, const std::vector<size_t>& order,
                         const std::string& settings_json, const MergeOptions& options, const Context& ctx,
                         DdgiResult& result, DdgiReport& report);

// Reads, checks and merges the parts and writes `out` atomically (never over a part); nothing is
// written when any part is missing, duplicated, foreign or corrupt.
Status merge_shard_files(const MergeOptions& options, const Context& ctx, MergeReport& report);

}  // namespace gibake
