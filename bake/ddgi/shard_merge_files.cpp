// merge_shard_files (shard_merge.h): parts read and checked, the bake finished, the file written.
#include <chrono>
#include <nlohmann/json.hpp>

#include "bake/ddgi/ddgi_metadata.h"
#include "bake/ddgi/shard_merge.h"
#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_shard.h"

namespace gibake {

Status merge_shard_files(const MergeOptions& o, const Context& ctx, MergeReport& report) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  report = MergeReport{};
  if (o.parts.empty()) return Status::error(ExitCode::BadArguments, "", "merge", "no shard files given");
  std::vector<DdgiShard> shards(o.parts.size());
  std::vector<RawSection> lpv;  // the global shard's cascades
  for (size_t i = 0; i < o.parts.size(); ++i) {
    std::vector<RawSection> found;
    GIBAKE_TRY(read_shard_file(o.parts[i], shards[i], &found));
    if (shards[i].global) lpv = std::move(found);
  }
  std::vector<size_t> order;
  GIBAKE_TRY(check_shard_set(o.parts, shards, order));
  report.stage_seconds.emplace_back("read", std::chrono::duration<double>(Clock::now() - t0).count());
  nlohmann::json meta = nlohmann::json::parse(shards[order[0]].metadata_json);
  nlohmann::json settings = meta.at("settings");
  settings.erase("lpv");
  const uint64_t input_hash = shards[order[0]].input_hash;
  const uint32_t sh_format = shards[order[0]].sh_format, atlas_format = shards[order[0]].atlas_format;
  report.shards = uint32_t(shards.size());
  DdgiResult result;
  GIBAKE_TRY(merge_ddgi_shards(shards, order, settings.dump(), o, ctx, result, report.ddgi));
  for (const auto& st : report.ddgi.stage_seconds) report.stage_seconds.push_back(st);
  shards.clear();
  add_ddgi_report_metadata(report.ddgi, meta);
  t0 = Clock::now();
  BakeOutputs outputs;
  outputs.ddgi = &result;
  outputs.extra = &lpv;
  outputs.metadata_json = meta.dump();
  outputs.input_hash = input_hash;
  BakeFileOptions file_options;
  file_options.sh = FloatPrecision(sh_format);
  file_options.atlas = FloatPrecision(atlas_format);
  file_options.warn = ctx.warn;
  file_options.threads = ctx.threads;
  GIBAKE_TRY(write_bake_file(o.out, outputs, file_options, o.parts));
  report.lpv = !lpv.empty();
  report.result.desc = result.desc;
  report.stage_seconds.emplace_back("write", std::chrono::duration<double>(Clock::now() - t0).count());
  return Status::ok();
}

}  // namespace gibake
