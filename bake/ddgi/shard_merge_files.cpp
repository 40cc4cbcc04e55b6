// merge_shard_files (shard_merge.h): parts read and checked, the bake finished, the file written.
#include <memory>
#include <nlohmann/json.hpp>

#include "bake/ddgi/ddgi_metadata.h"
#include "bake/ddgi/shard_merge.h"
#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_shard.h"
#include "io/timer.h"

namespace gibake {

namespace {

// The merged volumes' active probes into the metadata's volume list (the shards leave them 0).
void set_volume_activity(const std::vector<DdgiReport>& reports, nlohmann::json& meta) {
  if (!meta.contains("ddgi_volumes")) return;
  nlohmann::json& list = meta["ddgi_volumes"];
  for (size_t v = 0; v < list.size() && v < reports.size(); ++v) list[v]["active"] = reports[v].active;
}

}  // namespace

Status merge_shard_files(const MergeOptions& o, const Context& ctx, MergeReport& report) {
  auto t0 = Clock::now();
  report = MergeReport{};
  if (o.parts.empty()) return Status::error(ExitCode::BadArguments, "", "merge", "no shard files given");
  // Part by part: read, checked against the first, each volume added to its assembly (probe data
  // released), so a merge holds one decoded part at a time.
  std::vector<DdgiShard> first, part;
  std::vector<RawSection> lpv;  // the global shard's cascades
  std::vector<size_t> order;
  std::vector<DdgiResult> results;
  std::vector<std::unique_ptr<ShardAssembly>> assemblies;
  for (size_t i = 0; i < o.parts.size(); ++i) {
    std::vector<RawSection> found;
    GIBAKE_TRY(read_shard_volumes(o.parts[i], i == 0 ? first : part, &found));
    std::vector<DdgiShard>& shards = i == 0 ? first : part;
    GIBAKE_TRY(check_shard_part(o.parts, first, shards, i, order));
    if (shards[0].global) lpv = std::move(found);
    if (assemblies.empty()) {
      results.resize(first.size());
      for (size_t v = 0; v < first.size(); ++v) assemblies.push_back(std::make_unique<ShardAssembly>(first[v], results[v]));
    }
    for (size_t v = 0; v < shards.size(); ++v) assemblies[v]->add(shards[v]);
  }
  GIBAKE_TRY(check_shards_complete(first[0], order));
  report.stage_seconds.emplace_back("read", seconds_since(t0));
  nlohmann::json meta = nlohmann::json::parse(first[0].metadata_json);
  nlohmann::json settings = meta.at("settings");
  settings.erase("lpv");
  const uint64_t input_hash = first[0].input_hash;
  const uint32_t sh_format = first[0].sh_format, atlas_format = first[0].atlas_format;
  report.shards = uint32_t(order.size());
  report.volumes = uint32_t(results.size());
  std::vector<DdgiReport> reports(results.size());
  for (size_t v = 0; v < results.size(); ++v) {
    // As in the bake: a refined volume's dark probes are no warning (run_context.h warn_black).
    const bool refined = meta.contains("ddgi_volumes") && meta["ddgi_volumes"].size() > v &&
                         meta["ddgi_volumes"][v].value("kind", "") == "refined";
    GIBAKE_TRY(assemblies[v]->finish(settings.dump(), o, ctx, reports[v], !refined));
    for (const auto& st : reports[v].stage_seconds)
      report.stage_seconds.emplace_back(v == 0 ? st.first : "volume " + std::to_string(v) + " " + st.first, st.second);
    assemblies[v].reset();
  }
  report.ddgi = reports[0];
  first.clear();
  part.clear();
  add_ddgi_report_metadata(report.ddgi, meta);
  set_volume_activity(reports, meta);
  t0 = Clock::now();
  BakeOutputs outputs;
  outputs.ddgi = &results[0];
  for (size_t v = 1; v < results.size(); ++v) outputs.ddgi_more.push_back(&results[v]);
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
  report.result.desc = results[0].desc;
  report.stage_seconds.emplace_back("write", seconds_since(t0));
  return Status::ok();
}

}  // namespace gibake
