// `gibake merge part_*.gibake --out probes.gibake`: checks that shard files (bake/ddgi/shard_bake.h)
// belong together and finishes the bake from them: the probe-feedback bounce passes over every
// probe, the atlases, states, counts and the file, byte-identical to the same bake made in one go.
// The LPV cascades come from the shard that baked them (the global one), copied byte for byte.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/run/backend.h"
#include "io/bakefile/bake_file.h"
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
  // Where such bounce passes get their device (bake/pipeline/devices.h); null: only merges whose
  // bounce passes run on the CPU.
  const DdgiPlatform* platform = nullptr;
  // Parts of a bake that refines by check (--refine-by-check) are refused: its pass reads the scene,
  // so the bake's own command finishes it (`gibake bake ... --from-shards`), which sets this.
  bool check_refinement = false;
  // The caller's open GpuSession for such bounce passes (its device must be the shards'); null: the
  // merge opens one.
  GpuSession* session = nullptr;
  // Optional: a check of part 0's volumes, once read, before any other part is (the caller's own
  // expectations of the bake).
  std::function<Status(const std::vector<DdgiShard>& first)> check_first;
};

struct MergeReport {
  DdgiReport ddgi;    // the first volume's
  DdgiResult result;  // the first volume's grid only (desc): the arrays are released once written
  uint32_t volumes = 1;
  uint32_t shards = 0;
  bool lpv = false;  // LPV cascades copied from the global shard
  std::vector<std::pair<std::string, double>> stage_seconds;
};

// Part i (`part`, its volumes, read from paths[i]) belongs with part 0 (`first`): the same input
// hash, settings hash, shard count, volumes, grids and storage formats, and an index no earlier part
// had. `order[k]`: the part holding shard k (SIZE_MAX until one does). InvalidInput naming the part.
Status check_shard_part(const std::vector<std::string>& paths, const std::vector<DdgiShard>& first,
                        const std::vector<DdgiShard>& part, size_t i, std::vector<size_t>& order);
// Every shard present (`first`: a part's first volume); else InvalidInput naming the missing shard
// and its probe blocks.
Status check_shards_complete(const DdgiShard& first, const std::vector<size_t>& order);

// The assembled probes of a merge: checked parts added one at a time (their probe data released
// as it is copied, so a merge holds one decoded part at a time), then finished into `result`.
class ShardAssembly {
 public:
  ShardAssembly(const DdgiShard& first, DdgiResult& result);
  ~ShardAssembly();
  void add(DdgiShard& shard);
  // `settings_json`: the bake's settings object (DDGI keys; "lpv" ignored).
  // `warn_black`: warn when no light reached any probe (not for a refined volume).
  Status finish(const std::string& settings_json, const MergeOptions& options, const Context& ctx, DdgiReport& report,
                bool warn_black = true);

 private:
  struct State;
  DdgiResult& result_;
  std::unique_ptr<State> state_;
};

// The GpuSession a probe-feedback bake made on Vulkan runs its bounce passes on, opened once for
// every volume; none (`out` left empty) for other bakes or when the options hand one in.
Status open_bounce_session(const std::string& settings_json, const MergeOptions& options,
                           std::shared_ptr<GpuSession>& out);

// The parts read, checked and finished, every volume, before anything is written.
struct MergedParts {
  std::vector<DdgiResult> results;  // every volume, in the file's order
  std::vector<DdgiReport> reports;
  std::string metadata_json;    // shard 0's, with the merged counts
  std::vector<RawSection> lpv;  // the global shard's cascades
  uint64_t input_hash = 0;
  uint32_t sh_format = 0, atlas_format = 0;
  uint32_t shards = 0;
  std::vector<std::pair<std::string, double>> stage_seconds;
};

// Reads, checks and finishes the parts (options.out unused). InvalidInput naming the part when one
// is missing, duplicated, foreign or corrupt; BadArguments for a check-refining bake's parts unless
// options.check_refinement.
Status merge_shard_parts(const MergeOptions& options, const Context& ctx, MergedParts& out);

// merge_shard_parts, then writes `out` atomically (never over a part); nothing is written when any
// part is missing, duplicated, foreign or corrupt.
Status merge_shard_files(const MergeOptions& options, const Context& ctx, MergeReport& report);

}  // namespace gibake
