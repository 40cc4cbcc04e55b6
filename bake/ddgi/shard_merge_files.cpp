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

// A part whose bake refines by check or fits its atlases to the surfaces cannot be finished here
// (MergeOptions::check_refinement): those stages read the scene.
Status check_merge_can_finish(const MergeOptions& o, const nlohmann::json& settings) {
  if (o.check_refinement) return Status::ok();
  const std::string finish =
      ", whose pass reads the scene: finish it with the shards' command line, --from-shards PART... in place of "
      "--shard (docs/cli/bake.md)";
  const uint64_t budget =
      settings.contains("probe_volumes") ? settings["probe_volumes"].value("refine_by_check", uint64_t(0)) : 0;
  if (budget != 0)
    return Status::error(ExitCode::BadArguments, o.parts[0], "settings",
                         "its bake refines by check (--refine-by-check " + std::to_string(budget) + ")" + finish);
  if (settings.contains("surface_fit"))
    return Status::error(ExitCode::BadArguments, o.parts[0], "settings",
                         "its bake fits the atlases to the surfaces (--surface-fit on)" + finish);
  return Status::ok();
}

}  // namespace

Status merge_shard_parts(const MergeOptions& o, const Context& ctx, MergedParts& out) {
  auto t0 = Clock::now();
  out = MergedParts{};
  if (o.parts.empty()) return Status::error(ExitCode::BadArguments, "", "merge", "no shard files given");
  // Part by part: read, checked against the first, each volume added to its assembly (probe data
  // released), so a merge holds one decoded part at a time.
  std::vector<DdgiShard> first, part;
  nlohmann::json meta;  // part 0's metadata: the bake's settings and volume list
  std::vector<size_t> order;
  std::vector<std::unique_ptr<ShardAssembly>> assemblies;
  for (size_t i = 0; i < o.parts.size(); ++i) {
    std::vector<RawSection> found;
    GIBAKE_TRY(read_shard_volumes(o.parts[i], i == 0 ? first : part, &found));
    std::vector<DdgiShard>& shards = i == 0 ? first : part;
    GIBAKE_TRY(check_shard_part(o.parts, first, shards, i, order));
    if (i == 0) {
      meta = nlohmann::json::parse(first[0].metadata_json, nullptr, false);
      if (!meta.is_object() || !meta.contains("settings"))
        return Status::invalid(o.parts[0], "metadata", "not the JSON object of a bake's settings");
      GIBAKE_TRY(check_merge_can_finish(o, meta.at("settings")));
      if (o.check_first) GIBAKE_TRY(o.check_first(first));
    }
    if (shards[0].global) out.lpv = std::move(found);
    if (assemblies.empty()) {
      out.results.resize(first.size());
      for (size_t v = 0; v < first.size(); ++v)
        assemblies.push_back(std::make_unique<ShardAssembly>(first[v], out.results[v]));
    }
    for (size_t v = 0; v < shards.size(); ++v) assemblies[v]->add(shards[v]);
  }
  GIBAKE_TRY(check_shards_complete(first[0], order));
  out.stage_seconds.emplace_back("read", seconds_since(t0));
  nlohmann::json settings = meta.at("settings");
  settings.erase("lpv");
  const std::string settings_text = settings.dump();
  out.input_hash = first[0].input_hash;
  out.sh_format = first[0].sh_format;
  out.atlas_format = first[0].atlas_format;
  out.shards = uint32_t(order.size());
  out.reports.resize(out.results.size());
  std::shared_ptr<GpuSession> session;
  MergeOptions finishing = o;
  GIBAKE_TRY(open_bounce_session(settings_text, o, session));
  if (session) finishing.session = session.get();
  for (size_t v = 0; v < out.results.size(); ++v) {
    // As in the bake: a refined volume's dark probes are no warning (run_context.h warn_black).
    const bool refined = meta.contains("ddgi_volumes") && meta["ddgi_volumes"].size() > v &&
                         meta["ddgi_volumes"][v].value("kind", "") == "refined";
    GIBAKE_TRY(assemblies[v]->finish(settings_text, finishing, ctx, out.reports[v], !refined));
    for (const auto& st : out.reports[v].stage_seconds)
      out.stage_seconds.emplace_back(v == 0 ? st.first : "volume " + std::to_string(v) + " " + st.first, st.second);
    assemblies[v].reset();
  }
  add_ddgi_report_metadata(out.reports[0], meta);
  set_volume_activity(out.reports, meta);
  out.metadata_json = meta.dump();
  return Status::ok();
}

Status merge_shard_files(const MergeOptions& o, const Context& ctx, MergeReport& report) {
  report = MergeReport{};
  MergedParts merged;
  GIBAKE_TRY(merge_shard_parts(o, ctx, merged));
  report.shards = merged.shards;
  report.volumes = uint32_t(merged.results.size());
  report.ddgi = merged.reports[0];
  report.stage_seconds = std::move(merged.stage_seconds);
  const auto t0 = Clock::now();
  BakeOutputs outputs;
  outputs.ddgi = &merged.results[0];
  for (size_t v = 1; v < merged.results.size(); ++v) outputs.ddgi_more.push_back(&merged.results[v]);
  outputs.extra = &merged.lpv;
  outputs.metadata_json = merged.metadata_json;
  outputs.input_hash = merged.input_hash;
  BakeFileOptions file_options;
  file_options.sh = FloatPrecision(merged.sh_format);
  file_options.atlas = FloatPrecision(merged.atlas_format);
  file_options.warn = ctx.warn;
  file_options.threads = ctx.threads;
  GIBAKE_TRY(write_bake_file(o.out, outputs, file_options, o.parts));
  report.lpv = !merged.lpv.empty();
  report.result.desc = merged.results[0].desc;
  report.stage_seconds.emplace_back("write", seconds_since(t0));
  return Status::ok();
}

}  // namespace gibake
