// The finishing run of a sharded bake that refines by check (shard_finish.h).
#include "bake/pipeline/shard_finish.h"

#include <cstdio>

#include "bake/ddgi/shard_merge.h"
#include "bake/pipeline/stages.h"
#include "io/bakefile/input_digest.h"
#include "io/timer.h"

namespace gibake {

namespace {

// The input hash a shard of this command would record: the scene's digest and the file's settings.
Status expected_input_hash(const BakeRequest& r, const BakeResult& run, uint64_t& hash) {
  const std::pair<Status, InputDigest>& inputs = run.input_digest.get();
  GIBAKE_TRY(inputs.first);
  hash = content_input_hash(inputs.second, bake_file_settings_json(r, run), gibake_version_string());
  return Status::ok();
}

// The parts belong to this command: the same scene, settings and gibake (the input hash covers
// them) and so the same volumes. Checked on the first part, before the others are read.
Status check_parts_match(const BakeRequest& r, const BakeResult& run, const std::vector<DdgiShard>& first) {
  uint64_t expected = 0;
  GIBAKE_TRY(expected_input_hash(r, run, expected));
  const std::string& part = r.from_shards[0];
  if (first.empty() || first[0].input_hash != expected)
    return Status::invalid(part, "input hash",
                           "the shards were baked from another scene, other settings or another gibake than this "
                           "command (" +
                               hash_text(first.empty() ? 0 : first[0].input_hash) + ", this command " +
                               hash_text(expected) +
                               "): give the shards' command line with --from-shards in place "
                               "of --shard");
  if (first.size() != run.volumes.size())
    return Status::invalid(
        part, "shard_info",
        std::to_string(first.size()) + " probe volumes, this command plans " + std::to_string(run.volumes.size()));
  for (size_t v = 0; v < run.volumes.size(); ++v) {
    const DdgiVolumeDesc &a = first[v].desc, &b = run.volumes[v].result.desc;
    if (a.counts != b.counts || a.grid_min != b.grid_min || a.spacing != b.spacing)
      return Status::invalid(part, "shard_info", "volume " + std::to_string(v) + "'s grid differs from this command's");
  }
  return Status::ok();
}

}  // namespace

DdgiShardRun no_probes_shard_run(std::vector<DdgiShard>& volumes_out) {
  DdgiShardRun run;
  run.range.index = 1;  // shard 1 of 1: past the last block of every volume
  run.range.count = 1;
  run.volumes_out = &volumes_out;
  return run;
}

Status take_volumes_from_shards(const BakeRequest& r, const Context& ctx, RunContext& shared, BakeResult& run) {
  const auto t0 = Clock::now();
  MergeOptions options;
  options.parts = r.from_shards;
  options.backend = r.ddgi_settings.backend;
  options.platform = shared.platform;
  options.check_refinement = true;
  options.session = run.gpu.get();  // a Vulkan --gather probes bake's bounce passes: this run's device
  options.check_first = [&](const std::vector<DdgiShard>& first) { return check_parts_match(r, run, first); };
  MergedParts merged;
  GIBAKE_TRY(merge_shard_parts(options, ctx, merged));
  // The probes are the parts'; each volume keeps the settings this run placed it with, which the
  // file's volume list reads (its rays) and the shards recorded in the same words.
  for (size_t v = 0; v < run.volumes.size(); ++v) {
    BakedVolume& volume = run.volumes[v];
    std::string settings = std::move(volume.result.settings_json);
    volume.result = std::move(merged.results[v]);
    volume.result.settings_json = std::move(settings);
    volume.report = std::move(merged.reports[v]);
  }
  for (const auto& [stage, sec] : merged.stage_seconds) run.timings.emplace_back("shards: " + stage, sec);
  run.timings.emplace_back("shards (read, finished)", seconds_since(t0));
  ctx.note("from shards: " + std::to_string(merged.shards) + " shard(s) of " + std::to_string(run.volumes.size()) +
           " probe volume(s) read and finished");
  run.shards.clear();
  run.shard_run = DdgiShardRun{};
  shared.shard = nullptr;
  return Status::ok();
}

}  // namespace gibake
