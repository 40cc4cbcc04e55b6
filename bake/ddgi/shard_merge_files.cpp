// merge_shard_files (shard_merge.h): parts read and checked, the bake finished, the file written.
#include <memory>
#include <nlohmann/json.hpp>

#include "bake/ddgi/ddgi_metadata.h"
#include "bake/ddgi/shard_merge.h"
#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_shard.h"
#include "io/timer.h"

namespace gibake {

Status merge_shard_files(const MergeOptions& o, const Context& ctx, MergeReport& report) {
  auto t0 = Clock::now();
  report = MergeReport{};
  if (o.parts.empty()) return Status::error(ExitCode::BadArguments, "", "merge", "no shard files given");
  // Part by part: read, checked against the first, added to the assembly (probe data released).
  std::vector<DdgiShard> shards(o.parts.size());
  std::vector<RawSection> lpv;  // the global shard's cascades
  std::vector<size_t> order;
  DdgiResult result;
  std::unique_ptr<ShardAssembly> assembly;
  for (size_t i = 0; i < o.parts.size(); ++i) {
    std::vector<RawSection> found;
    GIBAKE_TRY(read_shard_file(o.parts[i], shards[i], &found));
    GIBAKE_TRY(check_shard_part(o.parts, shards, i, order));
    if (shards[i].global) lpv = std::move(found);
    if (!assembly) assembly = std::make_unique<ShardAssembly>(shards[0], result);
    assembly->add(shards[i]);
  }
  GIBAKE_TRY(check_shards_complete(shards[0], order));
  report.stage_seconds.emplace_back("read", seconds_since(t0));
  nlohmann::json meta = nlohmann::json::parse(shards[0].metadata_json);
  nlohmann::json settings = meta.at("settings");
  settings.erase("lpv");
  const uint64_t input_hash = shards[0].input_hash;
  const uint32_t sh_format = shards[0].sh_format, atlas_format = shards[0].atlas_format;
  report.shards = uint32_t(shards.size());
  GIBAKE_TRY(assembly->finish(settings.dump(), o, ctx, report.ddgi));
  for (const auto& st : report.ddgi.stage_seconds) report.stage_seconds.push_back(st);
  assembly.reset();
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
  report.stage_seconds.emplace_back("write", seconds_since(t0));
  return Status::ok();
}

}  // namespace gibake
