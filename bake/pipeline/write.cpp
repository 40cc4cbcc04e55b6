// The files of a bake request, after its stages: the bake file (or a shard file) with the
// reconstruction check read from its bytes while they are committed, the leak audit beside the
// write, the depfile.
#include <nlohmann/json.hpp>

#include "bake/ddgi/ddgi_metadata.h"
#include "bake/pipeline/devices.h"
#include "bake/pipeline/shard_finish.h"
#include "bake/pipeline/stages.h"
#include "io/bakefile/bake_shard.h"
#include "io/output/depfile.h"
#include "io/timer.h"

namespace gibake {
namespace {

// What a depfile lists: every file the bake read (the scene's, the sky map, the parts it finished)
// and the images the scene names that were missing.
std::vector<std::string> depfile_inputs(const BakeRequest& r, const BakeResult& run) {
  std::vector<std::string> inputs = run.scene.input_files;
  inputs.insert(inputs.end(), run.scene.missing_inputs.begin(), run.scene.missing_inputs.end());
  if (!r.ddgi_settings.sky_hdr.empty()) inputs.push_back(r.ddgi_settings.sky_hdr);
  inputs.insert(inputs.end(), r.from_shards.begin(), r.from_shards.end());
  return inputs;
}

// The bake file's metadata: settings of every stage, probe and ray counts; timings only when asked
// for, since they change from run to run and the file is otherwise byte-identical.
nlohmann::json bake_metadata(const BakeRequest& r, const BakeResult& run, nlohmann::json settings,
                             const InputDigest& inputs) {
  nlohmann::json meta{{"tool", "gibake"},
                      {"version", gibake_version_string()},
                      {"scene", r.files.scene},
                      {"settings", std::move(settings)},
                      {"inputs", input_digest_json(inputs)}};
  if (r.ddgi) add_ddgi_report_metadata(run.ddgi_report(), meta);
  if (r.ddgi && run.list_volumes()) meta["ddgi_volumes"] = nlohmann::json::parse(volumes_json(run.volumes));
  if (r.metadata_timings) {
    meta["threads"] = r.threads;
    nlohmann::json timings = nlohmann::json::object();
    for (const auto& [stage, sec] : run.timings) timings[stage] = sec;
    meta["timings_s"] = timings;
  }
  return meta;
}

// A shard bake: the shard file (bake/ddgi/shard_bake.h) with the bake's hash, settings and
// metadata; the global shard (0) carries the LPV cascades.
Status write_shard(const BakeRequest& r, BakeResult& run, const Context& ctx, BakeFileOptions file_options,
                   nlohmann::json settings, const InputDigest& inputs, uint64_t hash) {
  const uint64_t settings_hash = hash_settings(settings.dump());
  nlohmann::json meta = bake_metadata(r, run, std::move(settings), inputs);
  for (const char* key : {"probes", "closed_mesh_check", "rays"}) meta.erase(key);  // the merge's
  // The volumes' active counts are the merge's too (it sets them from the merged states).
  if (meta.contains("ddgi_volumes"))
    for (nlohmann::json& v : meta["ddgi_volumes"]) v["active"] = 0;
  const bool global = run.shard_run.range.index == 0;
  for (DdgiShard& shard : run.shards) {
    shard.input_hash = hash;
    shard.settings_hash = settings_hash;
    shard.sh_format = uint32_t(file_options.sh);
    shard.atlas_format = uint32_t(file_options.atlas);
    shard.global = global;
    shard.metadata_json = meta.dump();
  }
  file_options.warn = ctx.warn;
  file_options.threads = r.threads;
  const LpvResult* lpv = r.lpv && global ? &run.lpv : nullptr;
  GIBAKE_TRY(write_shard_file(r.files.out, run.shards, lpv, file_options, run.scene.input_files));
  if (!r.files.depfile.empty()) GIBAKE_TRY(write_depfile(r.files.depfile, r.files.out, depfile_inputs(r, run)));
  return Status::ok();
}

// How much of the atlases the stream wrote while the bake still ran (the rest after it).
void note_streamed(BakeFileStream& s, const Context& ctx) {
  using A = BakeFileStream;
  ctx.note("write: " + std::to_string(s.rows_written(A::kIrradiance)) + " of " +
           std::to_string(s.rows(A::kIrradiance)) + " irradiance and " + std::to_string(s.rows_written(A::kDepth)) +
           " of " + std::to_string(s.rows(A::kDepth)) + " depth atlas rows written during the bake");
}

// Every kind's settings as the file records them. A shard without the global volumes records the
// LPV settings it would have baked with (CPU only).
nlohmann::json file_settings(const BakeRequest& r, const BakeResult& run) {
  nlohmann::json settings = r.ddgi ? nlohmann::json::parse(run.ddgi().settings_json) : nlohmann::json::object();
  if (r.lpv) {
    LpvSettings cpu = r.lpv_settings;
    cpu.backend = BackendSettings{};
    settings["lpv"] =
        nlohmann::json::parse(run.lpv.settings_json.empty() ? lpv_settings_json(cpu) : run.lpv.settings_json);
  }
  if (r.vxgi) settings["vxgi"] = nlohmann::json::parse(run.vxgi.settings_json);
  return settings;
}

}  // namespace

std::string bake_file_settings_json(const BakeRequest& r, const BakeResult& run) {
  return file_settings(r, run).dump();
}

namespace {

// `while_committing` (optional) reads the finished file's bytes while they are committed to disk.
Status write_outputs(const BakeRequest& r, BakeResult& run, const Context& ctx,
                     const BytesReader& while_committing = {}) {
  nlohmann::json settings = file_settings(r, run);
  BakeFileOptions file_options = r.file_options;
  const auto t_write = Clock::now();
  const std::pair<Status, InputDigest>& inputs = run.input_digest.get();  // started after the import
  GIBAKE_TRY(inputs.first);
  const uint64_t hash = content_input_hash(inputs.second, settings.dump(), gibake_version_string());
  if (run.shard_run.volumes_out) return write_shard(r, run, ctx, file_options, std::move(settings), inputs.second, hash);
  BakeOutputs outputs;
  if (r.ddgi) outputs.ddgi = &run.ddgi();
  for (size_t i = 1; r.ddgi && i < run.volumes.size(); ++i) outputs.ddgi_more.push_back(&run.volumes[i].result);
  if (r.lpv) outputs.lpv = &run.lpv;
  if (r.vxgi) outputs.vxgi = &run.vxgi;
  outputs.metadata_json = bake_metadata(r, run, std::move(settings), inputs.second).dump();
  outputs.input_hash = hash;
  file_options.warn = ctx.warn;
  file_options.threads = r.threads;
  file_options.stream = run.file_stream.get();
  std::vector<std::pair<std::string, double>> parts;  // after "write", which holds them
  parts.emplace_back("write: inputs hashed, metadata", seconds_since(t_write));
  file_options.timing = [&parts](const char* part, double seconds) {
    parts.emplace_back(std::string("write: ") + part, seconds);
  };
  std::vector<std::string> inputs_kept = run.scene.input_files;  // never written over: the parts neither
  inputs_kept.insert(inputs_kept.end(), r.from_shards.begin(), r.from_shards.end());
  GIBAKE_TRY(write_bake_file(r.files.out, outputs, file_options, inputs_kept, while_committing));
  if (run.file_stream && run.file_stream->adopted()) note_streamed(*run.file_stream, ctx);
  if (!r.files.depfile.empty()) GIBAKE_TRY(write_depfile(r.files.depfile, r.files.out, depfile_inputs(r, run)));
  // The check reads the file while it is committed: the stage's time then holds the check's too.
  run.timings.emplace_back(while_committing ? "write (and the reconstruction check beside it)" : "write",
                           seconds_since(t_write));
  run.timings.insert(run.timings.end(), parts.begin(), parts.end());
  return Status::ok();
}

// How the written file's probes reconstruct irradiance at surface points, against the path tracer,
// in two halves. The reference (the patches from the bake's active probes, their path-traced light)
// is traced beside the file's encoding and write, from the results and settings the file will hold;
// the baked half reads the file's own bytes through the runtime loader while they are committed to
// disk (the same bytes the file holds, checksums already verified by the writer's self-check), so
// what is measured is what an engine loads, without waiting for the disk or reading the file back.
ReconstructionSettings check_settings(const BakeRequest& r, const BakeResult& run) {
  ReconstructionSettings rs;
  rs.patches = r.check.patches;
  rs.rays = r.check.rays;
  rs.target_noise = r.check.target_noise;
  rs.ray_budget = r.check.ray_budget;
  rs.seed = r.ddgi_settings.seed;
  rs.width = r.check.width;
  rs.height = r.check.height;
  rs.cameras = run.check_cameras;
  return rs;
}

// `device`: where the paths are traced (null: the CPU), handed to the session's closing once they are.
Status trace_check_reference(const BakeRequest& r, const Context& ctx, BakeResult& run,
                             std::unique_ptr<ReferencePathDevice> device, ReconstructionReference& out) {
  std::vector<const DdgiResult*> volumes;
  for (const BakedVolume& v : run.volumes) volumes.push_back(&v.result);
  ReconstructionSettings rs = check_settings(r, run);
  rs.device = device.get();
  const Status st = trace_bake_reconstruction_reference(*run.prepared, run.lod, run.volumes[0].result.settings_json,
                                                        active_probe_positions(volumes), rs, ctx, out);
  run.closing_session.release(std::move(device));
  if (st && !out.device.empty())
    ctx.note("reconstruction check: reference paths traced on " + out.device + " (" + std::to_string(out.seconds) +
             " s with the patches)");
  return st;
}

Status finish_check(const BakeRequest& r, const Context& ctx, BakeResult& run, const ReconstructionReference& reference,
                    const uint8_t* data, size_t size) {
  loader::BakeFile file;
  if (loader::Error e = file.open_borrowed(data, size, loader::LoadOptions{false}))
    return Status::invalid(r.files.out, loader::error_code_name(e.code), e.message);
  GIBAKE_TRY(finish_bake_reconstruction(*run.prepared, run.lod, file, reference, check_settings(r, run), ctx,
                                        run.reconstruction));
  run.have_reconstruction = true;
  run.timings.emplace_back("reconstruction check", run.reconstruction.seconds);
  return Status::ok();
}

// The bake file, with the check's reference traced beside its encoding and its baked half read
// from the bytes being committed.
Status write_with_check(const BakeRequest& r, const Context& ctx, BakeResult& run,
                        std::unique_ptr<ReferencePathDevice> check_device, bool check_wanted) {
  BytesReader check;
  ReconstructionReference reference;
  std::future<Status> referenced;  // waited for by its destructor on every way out
  if (check_wanted) {
    referenced = std::async(std::launch::async, [&] {
      return trace_check_reference(r, ctx, run, std::move(check_device), reference);
    });
    check = [&](const uint8_t* data, size_t size) {
      GIBAKE_TRY(referenced.get());
      return finish_check(r, ctx, run, reference, data, size);
    };
  }
  return write_outputs(r, run, ctx, check);
}

}  // namespace

Status finish_bake(const BakeRequest& r, const Context& ctx, BakeResult& run) {
  // No stage after these runs on the device: its session (the Vulkan device, the BVH and textures
  // on it) closes on a thread of its own while the file is written and checked, instead of when the
  // process ends.
  run.backend = run.gpu ? session_choice(*run.gpu) : BackendChoice{};
  run.had_session = run.gpu != nullptr;
  // The check's reference paths go to the device the probes were traced on, which then closes
  // after them. A shard holds no volume yet.
  const bool check_wanted = r.ddgi && !r.shard && r.check.enabled;
  std::unique_ptr<ReferencePathDevice> check_device = check_wanted ? make_reference_path_device(run.gpu) : nullptr;
  run.closing_session.release(std::move(run.gpu));
  double audit_seconds = 0.0;
  std::future<Status> audited;  // waited for by its destructor on every way out
  if (leak_audit_wanted(r, run) && leak_audit_beside_write(r))
    audited = std::async(std::launch::async, [&] { return run_leak_audit(r, ctx, run, audit_seconds); });
  if (r.ddgi || r.lpv || r.vxgi)
    GIBAKE_TRY(write_with_check(r, ctx, run, std::move(check_device), check_wanted));
  else if (!r.files.depfile.empty())
    GIBAKE_TRY(write_depfile(r.files.depfile, r.files.voxels_out, depfile_inputs(r, run)));
  if (!audited.valid()) return Status::ok();
  GIBAKE_TRY(audited.get());
  if (run.have_leak_audit) run.timings.emplace_back("leak audit", audit_seconds);
  return Status::ok();
}

Status run_bake(const BakeRequest& request, const Context& ctx, std::unique_ptr<BakeResult>& out) {
  out = std::make_unique<BakeResult>();
  BakeResult& run = *out;
  run.volume_settings = request.volumes;
  if (!request.from_shards.empty() &&
      (request.shard || (request.volumes.check_budget == 0 && !request.ddgi_settings.fit.enabled) || !request.ddgi))
    return Status::error(ExitCode::BadArguments, "", "--from-shards",
                         "finishes a --ddgi bake that refines by check (--refine-by-check) or fits its atlases to "
                         "the surfaces (--surface-fit on), not a shard; `gibake merge` finishes the others");
  if (request.shard) {
    run.shard_run.range.index = request.shard_index;
    run.shard_run.range.count = request.shard_count;
    run.shard_run.volumes_out = &run.shards;
  }
  if (!request.from_shards.empty()) run.shard_run = no_probes_shard_run(run.shards);
  GIBAKE_TRY(run_bake_stages(request, ctx, run));
  return finish_bake(request, ctx, run);
}

}  // namespace gibake
