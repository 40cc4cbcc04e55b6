// `gibake bake scene.gltf [--ddgi] [--lpv] [--out probes.bin] [--voxels scene.vdb] [options]` (the
// subcommand is implied). Stages run in order: import -> voxelize (+ .vdb; also when --lpv needs the
// grid) -> DDGI -> LPV -> bake file. This file only orders the stages; arguments become settings in
// bake_args.cpp and the summary is printed by bake_summary.cpp.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/ddgi_metadata.h"
#include "bake/ddgi/shard_bake.h"
#include "bake/ddgi/volumes.h"
#include "bake/lpv/lpv.h"
#include "bake/preview/reconstruction_check.h"
#include "bake/run/arena.h"
#include "bake/run/bake_setup.h"
#include "bake/run/devices.h"
#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/voxel/leak_audit.h"
#include "bake/voxel/voxelize.h"
#include "bake/vxgi/vxgi.h"
#include "cli/bake_args.h"
#include "cli/bake_report_page.h"
#include "cli/bake_summary.h"
#include "cli/check_camera.h"
#include "cli/commands.h"
#include "cli/leak_warnings.h"
#include "cli/progress.h"
#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_shard.h"
#include "io/bakefile/bake_stream.h"
#include "io/bakefile/input_digest.h"
#include "io/export/voxels_vdb.h"
#include "io/gltf/import.h"
#include "io/gltf/scene_inputs.h"
#include "io/output/depfile.h"
#include "io/output/output_check.h"
#include "io/timer.h"

#ifndef GIBAKE_VERSION
#define GIBAKE_VERSION "0.0.0"
#endif

namespace gibake::cli {
namespace {
// `warnings` collects what was printed, for --report.
Context make_context(const BakeArgs& a, const std::shared_ptr<Progress>& progress,
                     const std::shared_ptr<std::vector<std::string>>& warnings) {
  Context ctx = progress_context(progress, a.threads);
  auto warned = std::make_shared<std::mutex>();  // the leak audit warns beside the write
  ctx.warn = [progress, warnings, warned](const std::string& m) {
    std::lock_guard<std::mutex> lock(*warned);
    warnings->push_back(m);
    progress->clear();
    if (progress->mode() == ProgressMode::Json)
      progress->note("warning", m);
    else
      print_warning(m);
  };
  ctx.info = [progress, warned](const std::string& m) {  // the check notes beside the write too
    std::lock_guard<std::mutex> lock(*warned);
    progress->clear();
    if (progress->mode() == ProgressMode::Json)
      progress->note("info", m);
    else
      std::fprintf(stderr, "gibake: %s\n", m.c_str());
  };
  return ctx;
}

// Ends the process with `code` once stdout and stderr are flushed, every file being committed: the
// bake's memory (scene, textures, BVH, voxels, results: gigabytes at most) goes back to the system
// at once rather than piece by piece on the way out, 0.03 s after the heavy H100 bake
// (docs/BENCHMARKS.md), as compilers do (clang's -disable-free). Under AddressSanitizer it returns,
// so that LeakSanitizer still checks the teardown.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GIBAKE_UNDER_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define GIBAKE_UNDER_ASAN 1
#endif
void end_process_without_teardown(int code) {
#ifdef GIBAKE_UNDER_ASAN
  (void)code;
#else
  std::fflush(nullptr);
  std::_Exit(code);
#endif
}

// Everything the stages hand on to the bake file and the summary.
struct BakeRun {
  Scene scene;
  std::unique_ptr<PreparedScene> prepared;  // one Embree scene for every stage
  bool have_voxels = false;
  VoxelGrid voxels;
  VoxelReport voxel_report;
  // The DDGI volumes (bake/ddgi/volumes.h): the first is the one the leak audit, the summary's probe
  // counts and the report describe (the default grid unless --default-volume off).
  std::vector<BakedVolume> volumes = std::vector<BakedVolume>(1);
  std::string volume_rule;  // what the automatic detail-volume rule found
  VolumeSettings volume_settings;
  // Several volumes or a customised request: the file's metadata, the summary and the report list them.
  bool list_volumes() const { return volumes.size() > 1 || volume_settings.customised(); }
  DdgiResult& ddgi() { return volumes[0].result; }
  DdgiReport& ddgi_report() { return volumes[0].report; }
  const DdgiReport& ddgi_report() const { return volumes[0].report; }
  LpvResult lpv;
  VxgiResult vxgi;
  bool have_leak_audit = false;
  LeakAudit leaks;                     // every region
  std::vector<LeakExposure> exposure;  // per region: the bake's active probes across it
  std::vector<std::pair<std::string, double>> timings;
  VulkanWarmup vulkan_warmup;       // --ddgi on Vulkan: the device opening while the scene imports
  TextureLod lod;                   // the bake's texture mips, for the reconstruction check
  std::shared_ptr<GpuSession> gpu;  // the DDGI bake's device session, shared with the LPV (one context a process)
  bool have_reconstruction = false;
  std::vector<PreviewCamera> check_cameras;  // --check-camera, resolved right after the import
  ReconstructionError reconstruction;
  std::vector<DdgiShard> shards;  // --shard: this shard's probes of each volume, for the shard file
  DdgiShardRun shard_run;         // shard_run.volumes_out set when --shard was given
  // The scene's content and files hashed beside the stages (the file's input hash adds the settings
  // at the end); it reads `scene`, which nothing changes after the import, and its destructor waits.
  std::future<std::pair<Status, InputDigest>> input_digest;
  // Last, so that it goes first: its encoding reads the volumes' atlases (bake_stream.h).
  std::unique_ptr<BakeFileStream> file_stream;
};

// The voxelize stage (for --voxels, and as the LPV's geometry volume) and its .vdb: the scene's
// lights and --sun fill the direct channel.
Status run_voxels(const BakeArgs& a, const DdgiSettings& ddgi, const Context& ctx, BakeRun& run) {
  VoxelSettings vs;
  GIBAKE_TRY(to_voxel_settings(a, vs));
  const auto t0 = Clock::now();
  GIBAKE_TRY(voxelize(run.scene, vs, shade_lights(run.scene, ddgi.suns), run.prepared.get(), ctx, run.voxels,
                      &run.voxel_report));
  run.have_voxels = true;
  run.timings.emplace_back("voxelize", seconds_since(t0));
  return Status::ok();
}

// The --voxels .vdb, written after the stages: with --vxgi it also holds the voxel-GI grids.
Status write_voxels_file(const BakeArgs& a, BakeRun& run) {
  VoxelSettings vs;
  GIBAKE_TRY(to_voxel_settings(a, vs));
  const auto t_write = Clock::now();
  const VoxelVdbOptions options{voxel_settings_json(vs), a.scene, run.scene.input_files};
  GIBAKE_TRY(write_voxels_vdb(a.voxels, run.voxels, vxgi_vdb_grids(run.vxgi), options));  // none without --vxgi
  run.timings.emplace_back("write_vdb", seconds_since(t_write));
  return Status::ok();
}

// The bake file's metadata: settings of every stage, probe and ray counts; timings only when asked
// for, since they change from run to run and the file is otherwise byte-identical.
nlohmann::json bake_metadata(const BakeArgs& a, const BakeRun& run, nlohmann::json settings, const InputDigest& inputs) {
  nlohmann::json meta{{"tool", "gibake"},
                      {"version", GIBAKE_VERSION},
                      {"scene", a.scene},
                      {"settings", std::move(settings)},
                      {"inputs", input_digest_json(inputs)}};
  if (a.ddgi) add_ddgi_report_metadata(run.ddgi_report(), meta);
  if (a.ddgi && run.list_volumes()) meta["ddgi_volumes"] = nlohmann::json::parse(volumes_json(run.volumes));
  if (a.metadata_timings) {
    meta["threads"] = a.threads;
    nlohmann::json timings = nlohmann::json::object();
    for (const auto& [stage, sec] : run.timings) timings[stage] = sec;
    meta["timings_s"] = timings;
  }
  return meta;
}

// --shard: the shard file (bake/ddgi/shard_bake.h) with the bake's hash, settings and metadata; the
// global shard (0) carries the LPV cascades.
Status write_shard(const BakeArgs& a, BakeRun& run, const Context& ctx, BakeFileOptions file_options,
                   nlohmann::json settings, const InputDigest& inputs, uint64_t hash) {
  const uint64_t settings_hash = hash_settings(settings.dump());
  nlohmann::json meta = bake_metadata(a, run, std::move(settings), inputs);
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
  file_options.threads = a.threads;
  const LpvResult* lpv = a.lpv && global ? &run.lpv : nullptr;
  GIBAKE_TRY(write_shard_file(a.out, run.shards, lpv, file_options, run.scene.input_files));
  if (!a.depfile.empty()) GIBAKE_TRY(write_depfile(a.depfile, a.out, run.scene.input_files));
  return Status::ok();
}

// How much of the atlases the stream wrote while the bake still ran (the rest after it).
void note_streamed(BakeFileStream& s, const Context& ctx) {
  using A = BakeFileStream;
  ctx.note("write: " + std::to_string(s.rows_written(A::kIrradiance)) + " of " +
           std::to_string(s.rows(A::kIrradiance)) + " irradiance and " + std::to_string(s.rows_written(A::kDepth)) +
           " of " + std::to_string(s.rows(A::kDepth)) + " depth atlas rows written during the bake");
}

// `while_committing` (optional) reads the finished file's bytes while they are committed to disk.
Status write_outputs(const BakeArgs& a, BakeRun& run, const Context& ctx, BakeFileOptions file_options,
                     const BytesReader& while_committing = {}) {
  nlohmann::json settings = a.ddgi ? nlohmann::json::parse(run.ddgi().settings_json) : nlohmann::json::object();
  // A shard without the global volumes records the LPV settings it would have baked with (CPU only).
  if (a.lpv)
    settings["lpv"] =
        nlohmann::json::parse(run.lpv.settings_json.empty() ? lpv_settings_json(to_lpv_settings(a, BackendSettings{}))
                                                            : run.lpv.settings_json);
  if (a.vxgi.enabled) settings["vxgi"] = nlohmann::json::parse(run.vxgi.settings_json);
  const auto t_write = Clock::now();
  const std::pair<Status, InputDigest> inputs = run.input_digest.get();  // started after the import
  GIBAKE_TRY(inputs.first);
  const uint64_t hash = content_input_hash(inputs.second, settings.dump(), gibake_version_string());
  if (run.shard_run.volumes_out) return write_shard(a, run, ctx, file_options, std::move(settings), inputs.second, hash);
  BakeOutputs outputs;
  if (a.ddgi) outputs.ddgi = &run.ddgi();
  for (size_t i = 1; a.ddgi && i < run.volumes.size(); ++i) outputs.ddgi_more.push_back(&run.volumes[i].result);
  if (a.lpv) outputs.lpv = &run.lpv;
  if (a.vxgi.enabled) outputs.vxgi = &run.vxgi;
  outputs.metadata_json = bake_metadata(a, run, std::move(settings), inputs.second).dump();
  outputs.input_hash = hash;
  file_options.warn = ctx.warn;
  file_options.threads = a.threads;
  file_options.stream = run.file_stream.get();
  std::vector<std::pair<std::string, double>> parts;  // after "write", which holds them
  parts.emplace_back("write: inputs hashed, metadata", seconds_since(t_write));
  file_options.timing = [&parts](const char* part, double seconds) {
    parts.emplace_back(std::string("write: ") + part, seconds);
  };
  GIBAKE_TRY(write_bake_file(a.out, outputs, file_options, run.scene.input_files, while_committing));
  if (run.file_stream && run.file_stream->adopted()) note_streamed(*run.file_stream, ctx);
  if (!a.depfile.empty()) GIBAKE_TRY(write_depfile(a.depfile, a.out, run.scene.input_files));
  run.timings.emplace_back("write", seconds_since(t_write));  // with the check beside the commit, if any
  run.timings.insert(run.timings.end(), parts.begin(), parts.end());
  return Status::ok();
}

// How the written file's probes reconstruct irradiance at surface points, against the path tracer,
// in two halves. The reference (the patches from the bake's active probes, their path-traced light)
// is traced beside the file's encoding and write, from the results and settings the file will hold;
// the baked half reads the file's own bytes through the runtime loader while they are committed to
// disk (the same bytes the file holds, checksums already verified by the writer's self-check), so
// what is measured is what an engine loads, without waiting for the disk or reading the file back.
ReconstructionSettings check_settings(const BakeArgs& a, const DdgiSettings& settings, const BakeRun& run) {
  ReconstructionSettings rs;
  rs.patches = a.check_patches;
  rs.rays = a.check_rays;
  rs.seed = settings.seed;
  rs.width = kCheckWidth;
  rs.height = kCheckHeight;
  rs.cameras = run.check_cameras;
  return rs;
}

// `device`: where the paths are traced (null: the CPU), handed to `closing` once they are.
Status trace_check_reference(const BakeArgs& a, const DdgiSettings& settings, const Context& ctx, const BakeRun& run,
                             std::unique_ptr<ReferencePathDevice> device, ReleaseBeside& closing,
                             ReconstructionReference& out) {
  std::vector<const DdgiResult*> volumes;
  for (const BakedVolume& v : run.volumes) volumes.push_back(&v.result);
  ReconstructionSettings rs = check_settings(a, settings, run);
  rs.device = device.get();
  const Status st = trace_bake_reconstruction_reference(*run.prepared, run.lod, run.volumes[0].result.settings_json,
                                                        active_probe_positions(volumes), rs, ctx, out);
  closing.release(std::move(device));
  if (st && !out.device.empty())
    ctx.note("reconstruction check: reference paths traced on " + out.device + " (" + std::to_string(out.seconds) +
             " s with the patches)");
  return st;
}

Status finish_check(const BakeArgs& a, const DdgiSettings& settings, const Context& ctx, BakeRun& run,
                    const ReconstructionReference& reference, const uint8_t* data, size_t size) {
  loader::BakeFile file;
  if (loader::Error e = file.open_borrowed(data, size, loader::LoadOptions{false}))
    return Status::invalid(a.out, loader::error_code_name(e.code), e.message);
  GIBAKE_TRY(finish_bake_reconstruction(*run.prepared, run.lod, file, reference, check_settings(a, settings, run), ctx,
                                        run.reconstruction));
  run.have_reconstruction = true;
  run.timings.emplace_back("reconstruction check", run.reconstruction.seconds);
  return Status::ok();
}

// Thin walls between lit and unlit space, against the probe grid's coarsest spacing: warnings only
// where the bake's active probes blend across one (most light first), every region for the
// summary, the JSON and the report.
// `seconds` gets its time (the caller records it: beside the write, run.timings is the write's).
Status run_leak_audit(const DdgiSettings& settings, const Context& ctx, BakeRun& run, double& seconds) {
  const Stopwatch audit_time;
  GIBAKE_TRY(audit_bake_leaks(run.voxels, *run.prepared, shade_lights(run.scene, settings.suns), run.ddgi(), ctx,
                              run.leaks, run.exposure, run.have_leak_audit));
  seconds = audit_time.seconds();
  return Status::ok();
}

// The leak warnings weigh the final probe states, which a shard does not have (the merge makes them).
bool leak_audit_wanted(const BakeArgs& a, const BakeRun& run) {
  return a.ddgi && run.have_voxels && a.leak_audit == "on" && !run.shard_run.volumes_out;
}

// The audit reads the voxels, the scene and the final states, and the bake file does not record it:
// it runs beside the write and the reconstruction check (0.013-0.020 s off the H100 bakes' wall),
// except with --metadata-timings, whose timings in the file include it.
bool leak_audit_beside_write(const BakeArgs& a) { return !a.metadata_timings; }

// Every file the bake will write, against each other and against every file it reads (the scene,
// its buffers and images from a pre-read of its JSON, the sky HDR): refused before any work.
Status check_bake_paths(const BakeArgs& a) {
  std::vector<NamedPath> outputs;
  if (a.ddgi || a.lpv) outputs.push_back({"--out", a.out});
  if (!a.voxels.empty()) outputs.push_back({"--voxels", a.voxels});
  if (!a.report.empty()) outputs.push_back({"--report", a.report});
  if (!a.depfile.empty()) outputs.push_back({"--depfile", a.depfile});
  std::vector<NamedPath> inputs = scene_input_files(a.scene);
  if (!a.sky_hdr.empty()) inputs.push_back({"--sky-hdr", a.sky_hdr});
  return check_output_paths(outputs, inputs);
}

// --shard I/N: a probe bake, one file per shard, nothing that differs between shards' runs.
Status check_shard_args(const BakeArgs& a, const DdgiSettings& settings) {
  uint32_t index = 0, count = 0;
  GIBAKE_TRY(parse_shard(a.shard, index, count));
  if (!a.ddgi) return bad_arg("--shard", "shards split the DDGI probes: add --ddgi");
  if (!a.voxels.empty()) return bad_arg("--shard", "--voxels is not written by shards (bake it once without --shard)");
  if (!a.report.empty()) return bad_arg("--shard", "--report describes a whole bake; not with --shard");
  if (a.metadata_timings) return bad_arg("--shard", "--metadata-timings would make shards differ; not with --shard");
  if (a.lpv && settings.backend.backend == Backend::Vulkan)
    return bad_arg("--shard", "--lpv with --shard needs --backend cpu or auto (shard 0 bakes the LPV on the CPU)");
  return Status::ok();
}

// Every check that needs no scene, so that a typo fails before a long import.
Status check_args(const BakeArgs& a, ProgressMode& mode, DdgiSettings& settings, BakeFileOptions& file_options) {
  GIBAKE_TRY(refuse_bake_file_as_scene(a.scene));  // the mistake behind every other message
  const bool bake_file = a.ddgi || a.lpv || a.vxgi.enabled;
  if (!bake_file && a.voxels.empty())
    return bad_arg("bake", "nothing to bake: add --ddgi, --lpv, --vxgi and/or --voxels (e.g. gibake " +
                               (a.scene.empty() ? std::string("scene.gltf") : a.scene) + " --ddgi --out probes.bin)");
  if (bake_file && a.out.empty()) return bad_arg("--out", "an output file is required (--out probes.gibake)");
  if (bake_file) GIBAKE_TRY(check_bake_file_name("--out", a.out));
  if (!bake_file && !a.out.empty())
    return bad_arg("--out", "--out names the bake file of --ddgi/--lpv; --voxels names its own file");
  GIBAKE_TRY(parse_progress_option(a.progress, mode));
  GIBAKE_TRY(to_settings(a, settings));
  VolumeSettings volume_check;
  GIBAKE_TRY(to_volume_settings(a, volume_check));
  VoxelSettings voxel_check;
  GIBAKE_TRY(to_voxel_settings(a, voxel_check));
  if (a.lpv) {
    if (Status st = validate_lpv_settings(to_lpv_settings(a, settings.backend)); !st)
      return bad_arg("--lpv", st.what());
  }
  if (a.vxgi.enabled) {
    VxgiSettings vxgi_check;
    GIBAKE_TRY(to_vxgi_settings(a.vxgi, a.seed, a.blend_cutoff, vxgi_check));
    file_options.vxgi = a.vxgi.format == "auto"  ? FloatPrecision::Auto
                        : a.vxgi.format == "f16" ? FloatPrecision::Half
                                                 : FloatPrecision::Full;
  }
  bool leak_audit = true;
  GIBAKE_TRY(parse_on_off("--leak-audit", a.leak_audit, leak_audit));
  bool reconstruction_check = true;
  GIBAKE_TRY(parse_on_off("--reconstruction-check", a.reconstruction_check, reconstruction_check));
  GIBAKE_TRY(check_camera_specs(a.check_cameras, a.check_fov));
  if (!a.report.empty() && !a.ddgi) return bad_arg("--report", "the report describes a probe bake: add --ddgi");
  if (!parse_precision(a.sh_format, file_options.sh))
    return bad_arg("--sh-format", "expected f32, f16 or auto, got '" + a.sh_format + "'");
  if (!parse_precision(a.atlas_format, file_options.atlas))
    return bad_arg("--atlas-format", "expected auto, f16 or f32, got '" + a.atlas_format + "'");
  GIBAKE_TRY(check_bake_paths(a));
  if (!a.shard.empty()) GIBAKE_TRY(check_shard_args(a, settings));
  if (settings.backend.backend == Backend::Vulkan && a.lpv && !a.ddgi) {
    BackendChoice early;  // a missing device fails before the import (with --ddgi: the warm-up's start)
    GIBAKE_TRY(resolve_backend(settings.backend, early));
  }
  return Status::ok();
}

Status run_stages(const BakeArgs& a, const DdgiSettings& settings, const BakeFileOptions& file_options,
                  const Context& ctx, BakeRun& run) {
  RunContext shared;  // what the DDGI bake is handed instead of building it
  if (a.ddgi && settings.backend.backend != Backend::Cpu) {
    // The driver lists the devices and opens one while the scene is imported.
    GIBAKE_TRY(run.vulkan_warmup.start(settings.backend));
    shared.vulkan_warmup = &run.vulkan_warmup;
  }
  const auto t_import = Clock::now();
  ImportOptions import_options;
  // The driver lists the devices while the scene imports: a missing device stops the import and its
  // error (exit 4) is the one reported. A listing still under way is waited for by the set-up, which
  // reports the same error before it builds anything for the device.
  if (shared.vulkan_warmup) import_options.cancelled = [&run] { return run.vulkan_warmup.listing_failed(); };
  const Status imported = import_scene(a.scene, import_options, ctx, run.scene);
  if (shared.vulkan_warmup && run.vulkan_warmup.listing_failed()) GIBAKE_TRY(run.vulkan_warmup.listed());
  GIBAKE_TRY(imported);
  run.timings.emplace_back("import", seconds_since(t_import));
  // A whole DDGI bake's file is begun before the trace, its atlases written as their rows become
  // final (io/bakefile/bake_stream.h); the write after the bake adopts them or starts afresh.
  // The stream predicts a file of DDGI alone: none beside LPV or voxel GI sections, nor for a shard.
  if (a.ddgi && !a.lpv && !a.vxgi.enabled && !run.shard_run.volumes_out) {
    run.file_stream = std::make_unique<BakeFileStream>(a.out, run.scene.input_files, file_options);
    shared.file_stream = run.file_stream.get();
  }
  run.input_digest = std::async(std::launch::async, [&scene = run.scene] {
    InputDigest digest = digest_scene(scene);
    Status st = digest_files(scene.input_files, digest);
    return std::make_pair(std::move(st), std::move(digest));
  });
  GIBAKE_TRY(resolve_check_cameras(run.scene, a.check_cameras, a.check_fov, run.check_cameras));
  if (a.vxgi.enabled) {  // the voxel GI grid's size and memory are judged before any stage spends time
    VxgiSettings vxgi_plan;
    GIBAKE_TRY(to_vxgi_settings(a.vxgi, a.seed, a.blend_cutoff, vxgi_plan));
    VoxelGrid layout;
    uint64_t estimate = 0;
    GIBAKE_TRY(plan_vxgi(run.scene, vxgi_plan, layout, estimate));
  }
  // One Embree scene and one voxel grid for every stage.
  const bool full_voxels = !a.voxels.empty() || a.lpv;
  if (full_voxels || !a.ddgi) {
    const auto t_prepare = Clock::now();
    PrepareOptions options;
    options.blend_cutoff = a.blend_cutoff;
    GIBAKE_TRY(PreparedScene::create(run.scene, ctx, run.prepared, options));
    run.timings.emplace_back("prepare", seconds_since(t_prepare));
  }
  if (full_voxels) GIBAKE_TRY(run_voxels(a, settings, ctx, run));
  if (a.ddgi) {
    // The bake builds what it needs before its first ray (bake/run/bake_setup.h: the BVH, mips and
    // enclosure grid side by side, with its closed-mesh check already running beside them) and
    // leaves it in `setup`, so that the leak audit reads the enclosure grid too.
    BakeSetup setup;
    if (run.have_voxels) shared.voxels = &run.voxels;
    shared.prepared = run.prepared.get();
    shared.setup_out = &setup;
    if (run.shard_run.volumes_out) shared.shard = &run.shard_run;
    GIBAKE_TRY(bake_ddgi_volumes(run.scene, settings, run.volume_settings, shared, ctx, run.volumes, &run.volume_rule));
    for (size_t i = 0; i < run.volumes.size(); ++i)  // a later volume's stages named after it
      for (const auto& [stage, sec] : run.volumes[i].report.stage_seconds)
        run.timings.emplace_back(i == 0 ? stage : "volume " + std::to_string(i) + " " + stage, sec);
    if (!run.prepared) run.prepared = std::move(setup.prepared);
    run.lod = std::move(setup.lod);
    run.gpu = std::move(setup.gpu);
    if (!run.have_voxels) {
      run.voxels = std::move(setup.voxels);
      run.have_voxels = !run.voxels.empty();
    }
    if (leak_audit_wanted(a, run) && !leak_audit_beside_write(a)) {
      double seconds = 0.0;
      GIBAKE_TRY(run_leak_audit(settings, ctx, run, seconds));
      if (run.have_leak_audit) run.timings.emplace_back("leak audit", seconds);
    }
  }
  if (a.lpv && (!run.shard_run.volumes_out || run.shard_run.range.index == 0)) {
    // A shard's LPV is the CPU's whatever auto chose for its probes (the merge copies it as it is).
    GIBAKE_TRY(bake_lpv(run.scene, *run.prepared, shade_lights(run.scene, settings.suns), &run.voxels,
                        to_lpv_settings(a, settings.backend), ctx, run.lpv,
                        run.shard_run.volumes_out ? nullptr : run.gpu.get()));
    run.timings.emplace_back("lpv_vpls", run.lpv.stats.seconds_vpls);
    run.timings.emplace_back("lpv_propagate", run.lpv.stats.seconds_propagate);
  }
  if (a.vxgi.enabled) {
    GIBAKE_TRY(run_vxgi_stage(a.vxgi, settings, a.seed, a.blend_cutoff, run.scene, *run.prepared, ctx, run.vxgi));
    run.timings.emplace_back("vxgi_radiance", run.vxgi.stats.seconds_radiance);
    run.timings.emplace_back("vxgi_mips", run.vxgi.stats.seconds_mips);
  }
  if (!a.voxels.empty()) GIBAKE_TRY(write_voxels_file(a, run));
  return Status::ok();
}

int run_bake(const BakeArgs& a) {
  const auto t0 = Clock::now();
  ProgressMode mode;
  DdgiSettings settings;
  BakeFileOptions file_options;
  if (Status st = check_args(a, mode, settings, file_options); !st) return report_error(st);
  auto progress = std::make_shared<Progress>(mode);
  auto warnings = std::make_shared<std::vector<std::string>>();
  const Context ctx = make_context(a, progress, warnings);
  auto fail = [&](const Status& st) {
    progress->clear();
    return report_error(st);
  };

  // On the heap, so that its memory can go back beside the device's close at the end.
  auto run_memory = std::make_unique<BakeRun>();
  BakeRun& run = *run_memory;
  to_volume_settings(a, run.volume_settings);  // checked by check_args
  if (!a.shard.empty()) {
    parse_shard(a.shard, run.shard_run.range.index, run.shard_run.range.count);  // checked by check_args
    run.shard_run.volumes_out = &run.shards;
  }
  if (Status st = run_stages(a, settings, file_options, ctx, run); !st) return fail(st);
  // No stage after these runs on the device: its session (the Vulkan device, the BVH and textures
  // on it) closes on a thread of its own while the file is written and checked, instead of when the
  // process ends, where the driver's teardown took 0.04 s after a heavy bake (docs/BENCHMARKS.md).
  const BackendChoice backend = run.gpu ? session_choice(*run.gpu) : BackendChoice{};
  const bool had_session = run.gpu != nullptr;
  ReleaseBeside closing_session;  // after `run`: joined before it goes
  // The check's reference paths go to the device the probes were traced on, which then closes
  // after them.
  const bool check_wanted = a.ddgi && a.shard.empty() && a.reconstruction_check == "on";  // a shard holds no volume yet
  std::unique_ptr<ReferencePathDevice> check_device = check_wanted ? make_reference_path_device(run.gpu) : nullptr;
  closing_session.release(std::move(run.gpu));
  double audit_seconds = 0.0;
  std::future<Status> audited;  // waited for by its destructor on every way out
  if (leak_audit_wanted(a, run) && leak_audit_beside_write(a))
    audited = std::async(std::launch::async, [&] { return run_leak_audit(settings, ctx, run, audit_seconds); });
  const auto audit_done = [&]() -> Status {
    if (!audited.valid()) return Status::ok();
    GIBAKE_TRY(audited.get());
    if (run.have_leak_audit) run.timings.emplace_back("leak audit", audit_seconds);
    return Status::ok();
  };
  if (a.ddgi || a.lpv || a.vxgi.enabled) {
    BytesReader check;
    ReconstructionReference reference;
    std::future<Status> referenced;                                     // waited for by its destructor on every way out
    if (check_wanted) {
      referenced = std::async(std::launch::async, [&] {
        return trace_check_reference(a, settings, ctx, run, std::move(check_device), closing_session, reference);
      });
      check = [&](const uint8_t* data, size_t size) {
        GIBAKE_TRY(referenced.get());
        return finish_check(a, settings, ctx, run, reference, data, size);
      };
    }
    if (Status st = write_outputs(a, run, ctx, file_options, check); !st) return fail(st);
  } else if (!a.depfile.empty()) {
    if (Status st = write_depfile(a.depfile, a.voxels, run.scene.input_files); !st) return fail(st);
  }
  if (Status st = audit_done(); !st) return fail(st);
  if (!a.report.empty()) {
    const auto t_report = Clock::now();
    ReportPageInputs page;
    page.page = a.report;
    page.scene_path = a.scene;
    page.bake_path = a.out;
    page.blend_cutoff = a.blend_cutoff;
    page.scene = &run.scene;
    page.result = &run.ddgi();
    page.report = &run.ddgi_report();
    page.timings = run.timings;
    page.bake_start = t0;
    page.warnings = *warnings;
    if (run.have_leak_audit) page.leak_regions = leak_region_lines(run.leaks, run.exposure);
    if (run.have_reconstruction) page.reconstruction = &run.reconstruction;
    if (!a.check_cameras.empty()) {
      page.view = a.check_cameras.front();
      page.view_fov = a.check_fov;
    }
    if (run.list_volumes()) page.volumes_json = volumes_json(run.volumes);
    page.quality = quality_summary(a, settings, run.ddgi().desc.spacing[0]);
    if (Status st = write_report_page(page, ctx); !st) return fail(st);
    run.timings.emplace_back("report", seconds_since(t_report));
  }
  run.timings.emplace_back("total", seconds_since(t0));

  progress->clear();
  BakeSummary summary;
  summary.out = a.ddgi || a.lpv || a.vxgi.enabled ? a.out : a.voxels;
  if (!a.voxels.empty()) {
    if (a.ddgi || a.lpv || a.vxgi.enabled) summary.out += " and " + a.voxels;
    summary.voxels = &run.voxel_report;
    summary.voxels_out = a.voxels;
    summary.voxels_sizing = a.voxel_size > 0.f
                                ? "--voxel-size"
                                : std::to_string(a.voxel_res ? a.voxel_res : VoxelSettings{}.resolution) +
                                      " across the scene's longest side (--voxel-res)";
  }
  if (a.ddgi) {
    summary.result = &run.ddgi();
    summary.report = &run.ddgi_report();
    summary.target_error = settings.target_error;
    if (run.list_volumes()) {
      for (size_t i = 0; i < run.volumes.size(); ++i) summary.volume_lines.push_back(volume_line(i, run.volumes[i]));
      summary.volumes_json = volumes_json(run.volumes);
    }
    summary.volume_rule = run.volume_rule;
    summary.quality = quality_summary(a, settings, run.ddgi().desc.spacing[0]);
  }
  if (a.lpv && !run.lpv.cascades.empty()) summary.lpv = &run.lpv;
  if (run.have_leak_audit) {
    summary.leaks = &run.leaks;
    summary.leak_exposure = &run.exposure;
  }
  if (run.have_reconstruction) summary.reconstruction = &run.reconstruction;
  summary.timings = run.timings;
  if (a.ddgi && had_session) summary.backend = &backend;
  print_bake_summary(summary, progress->mode());
  if (a.vxgi.enabled) print_vxgi_summary(run.vxgi, progress->mode());
  // The bake's host memory (scene, BVH, mips, voxels, results: 0.5 GB after the medium H100 bake)
  // goes back beside the device's close, which the process waits for anyway, rather than in the
  // process's exit after it.
  ReleaseBeside freeing;
  freeing.release(std::move(run_memory));
  closing_session.wait();  // the device is closed: no driver call is cut short
  freeing.wait();
  end_process_without_teardown(0);
  return 0;
}

}  // namespace

const Command kBakeCommand{"bake", add_command<BakeArgs, add_bake_options, run_bake>};

}  // namespace gibake::cli
