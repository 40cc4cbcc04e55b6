// `gibake bake scene.gltf [--ddgi] [--lpv] [--out probes.bin] [--voxels scene.vdb] [options]` (the
// subcommand is implied). Stages run in order: import -> voxelize (+ .vdb; also when --lpv needs the
// grid) -> DDGI -> LPV -> bake file. This file only orders the stages; arguments become settings in
// bake_args.cpp and the summary is printed by bake_summary.cpp.

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/ddgi_metadata.h"
#include "bake/ddgi/shard_bake.h"
#include "bake/lpv/lpv.h"
#include "bake/preview/reconstruction_check.h"
#include "bake/run/bake_setup.h"
#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/voxel/leak_audit.h"
#include "bake/voxel/voxelize.h"
#include "cli/bake_args.h"
#include "cli/bake_report_page.h"
#include "cli/bake_summary.h"
#include "cli/commands.h"
#include "cli/leak_warnings.h"
#include "cli/progress.h"
#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_info.h"
#include "io/bakefile/bake_shard.h"
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
  Context ctx;
  ctx.threads = a.threads;
  ctx.warn = [progress, warnings](const std::string& m) {
    warnings->push_back(m);
    progress->clear();
    if (progress->mode() == ProgressMode::Json)
      progress->note("warning", m);
    else
      print_warning(m);
  };
  ctx.info = [progress](const std::string& m) {
    progress->clear();
    if (progress->mode() == ProgressMode::Json)
      progress->note("info", m);
    else
      std::fprintf(stderr, "gibake: %s\n", m.c_str());
  };
  ctx.progress = [progress](const std::string& stage, double done, double total) {
    progress->update(stage, done, total);
  };
  return ctx;
}

// Everything the stages hand on to the bake file and the summary.
struct BakeRun {
  Scene scene;
  std::unique_ptr<PreparedScene> prepared;  // one Embree scene for every stage
  bool have_voxels = false;
  VoxelGrid voxels;
  VoxelReport voxel_report;
  DdgiResult ddgi;
  DdgiReport ddgi_report;
  LpvResult lpv;
  VxgiResult vxgi;
  bool have_leak_audit = false;
  LeakAudit leaks;                     // every region
  std::vector<LeakExposure> exposure;  // per region: the bake's active probes across it
  std::vector<std::pair<std::string, double>> timings;
  VulkanWarmup vulkan_warmup;  // --ddgi on Vulkan: the device opening while the scene imports
  TextureLod lod;              // the bake's texture mips, for the reconstruction check
  GpuSession gpu;              // the DDGI bake's Vulkan session, shared with the LPV (one context a process)
  bool have_reconstruction = false;
  ReconstructionError reconstruction;
  DdgiShard shard;             // --shard: this shard's probes, for the shard file
  DdgiShardRun shard_run;      // shard_run.out set when --shard was given
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
  if (a.voxels.empty()) return Status::ok();
  const auto t_write = Clock::now();
  VoxelVdbOptions options;
  options.settings_json = voxel_settings_json(vs);
  options.scene = a.scene;
  options.inputs = run.scene.input_files;
  GIBAKE_TRY(write_voxels_vdb(a.voxels, run.voxels, {}, options));
  run.timings.emplace_back("write_vdb", seconds_since(t_write));
  return Status::ok();
}

// The bake file's metadata: settings of every stage, probe and ray counts; timings only when asked
// for, since they change from run to run and the file is otherwise byte-identical.
nlohmann::json bake_metadata(const BakeArgs& a, const BakeRun& run, nlohmann::json settings) {
  nlohmann::json meta{
      {"tool", "gibake"}, {"version", GIBAKE_VERSION}, {"scene", a.scene}, {"settings", std::move(settings)}};
  if (a.ddgi) add_ddgi_report_metadata(run.ddgi_report, meta);
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
                   nlohmann::json settings, uint64_t hash) {
  DdgiShard& shard = run.shard;
  shard.input_hash = hash;
  shard.settings_hash = hash_settings(settings.dump());
  shard.sh_format = uint32_t(file_options.sh);
  shard.atlas_format = uint32_t(file_options.atlas);
  shard.global = run.shard_run.range.index == 0;
  nlohmann::json meta = bake_metadata(a, run, std::move(settings));
  for (const char* key : {"probes", "closed_mesh_check", "rays"}) meta.erase(key);  // the merge's
  shard.metadata_json = meta.dump();
  file_options.warn = ctx.warn;
  file_options.threads = a.threads;
  const LpvResult* lpv = a.lpv && shard.global ? &run.lpv : nullptr;
  GIBAKE_TRY(write_shard_file(a.out, shard, lpv, file_options, run.scene.input_files));
  if (!a.depfile.empty()) GIBAKE_TRY(write_depfile(a.depfile, a.out, run.scene.input_files));
  return Status::ok();
}

Status write_outputs(const BakeArgs& a, BakeRun& run, const Context& ctx, BakeFileOptions file_options) {
  nlohmann::json settings = a.ddgi ? nlohmann::json::parse(run.ddgi.settings_json) : nlohmann::json::object();
  // A shard without the global volumes records the LPV settings it would have baked with (CPU only).
  if (a.lpv)
    settings["lpv"] = nlohmann::json::parse(run.lpv.settings_json.empty() ? lpv_settings_json(to_lpv_settings(a, BackendSettings{}))
                                                                           : run.lpv.settings_json);
  if (a.vxgi.enabled) settings["vxgi"] = nlohmann::json::parse(run.vxgi.settings_json);
  const auto t_write = Clock::now();
  uint64_t hash = 0;
  GIBAKE_TRY(hash_inputs(run.scene.input_files, settings.dump(), hash));
  if (run.shard_run.out) return write_shard(a, run, ctx, file_options, std::move(settings), hash);
  BakeOutputs outputs;
  if (a.ddgi) outputs.ddgi = &run.ddgi;
  if (a.lpv) outputs.lpv = &run.lpv;
  if (a.vxgi.enabled) outputs.vxgi = &run.vxgi;
  outputs.metadata_json = bake_metadata(a, run, std::move(settings)).dump();
  outputs.input_hash = hash;
  file_options.warn = ctx.warn;
  file_options.threads = a.threads;
  GIBAKE_TRY(write_bake_file(a.out, outputs, file_options, run.scene.input_files));
  if (!a.depfile.empty()) GIBAKE_TRY(write_depfile(a.depfile, a.out, run.scene.input_files));
  run.timings.emplace_back("write", seconds_since(t_write));
  return Status::ok();
}

// How the written file's probes reconstruct irradiance at surface points, against the path tracer:
// read back through the runtime loader, so what is measured is what an engine loads.
Status run_reconstruction_check(const BakeArgs& a, const DdgiSettings& settings, const Context& ctx, BakeRun& run) {
  const auto t0 = Clock::now();
  loader::BakeFile file;
  GIBAKE_TRY(open_bake_file(a.out, file));
  ReconstructionSettings rs;
  rs.patches = a.check_patches;
  rs.rays = a.check_rays;
  rs.seed = settings.seed;
  GIBAKE_TRY(measure_bake_reconstruction(*run.prepared, run.lod, file, 0, rs, ctx, run.reconstruction));
  run.have_reconstruction = true;
  run.timings.emplace_back("reconstruction check", seconds_since(t0));
  return Status::ok();
}

// Thin walls between lit and unlit space, against the probe grid's coarsest spacing: warnings only
// where the bake's active probes blend across one (most light first), every region for the
// summary, the JSON and the report.
Status run_leak_audit(const DdgiSettings& settings, const Context& ctx, BakeRun& run) {
  const Stopwatch audit_time;
  GIBAKE_TRY(audit_bake_leaks(run.voxels, *run.prepared, shade_lights(run.scene, settings.suns), run.ddgi, ctx,
                              run.leaks, run.exposure, run.have_leak_audit));
  if (run.have_leak_audit) run.timings.emplace_back("leak audit", audit_time.seconds());
  return Status::ok();
}

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
  const bool bake_file = a.ddgi || a.lpv || a.vxgi.enabled;
  if (!bake_file && a.voxels.empty())
    return bad_arg("bake", "nothing to bake: add --ddgi, --lpv, --vxgi and/or --voxels (e.g. gibake " +
                               (a.scene.empty() ? std::string("scene.gltf") : a.scene) + " --ddgi --out probes.bin)");
  if (bake_file && a.out.empty()) return bad_arg("--out", "an output file is required (--out probes.bin)");
  if (!bake_file && !a.out.empty())
    return bad_arg("--out", "--out names the bake file of --ddgi/--lpv; --voxels names its own file");
  if (!parse_progress_mode(a.progress, mode)) return bad_arg("--progress", "expected auto, bar, lines or json");
  GIBAKE_TRY(to_settings(a, settings));
  VoxelSettings voxel_check;
  GIBAKE_TRY(to_voxel_settings(a, voxel_check));
  if (a.lpv) {
    if (Status st = validate_lpv_settings(to_lpv_settings(a, settings.backend)); !st) return bad_arg("--lpv", st.what());
  }
  if (a.vxgi.enabled) {
    VxgiSettings vxgi_check;
    GIBAKE_TRY(to_vxgi_settings(a.vxgi, a.seed, a.blend_cutoff, vxgi_check));
    file_options.vxgi = a.vxgi.format == "auto" ? FloatPrecision::Auto
                        : a.vxgi.format == "f16" ? FloatPrecision::Half : FloatPrecision::Full;
  }
  bool leak_audit = true;
  GIBAKE_TRY(parse_on_off("--leak-audit", a.leak_audit, leak_audit));
  bool reconstruction_check = true;
  GIBAKE_TRY(parse_on_off("--reconstruction-check", a.reconstruction_check, reconstruction_check));
  if (!a.report.empty() && !a.ddgi) return bad_arg("--report", "the report describes a probe bake: add --ddgi");
  if (!parse_precision(a.sh_format, file_options.sh)) return bad_arg("--sh-format", "expected f32, f16 or auto");
  if (!parse_precision(a.atlas_format, file_options.atlas))
    return bad_arg("--atlas-format", "expected auto, f16 or f32");
  GIBAKE_TRY(check_bake_paths(a));
  if (!a.shard.empty()) GIBAKE_TRY(check_shard_args(a, settings));
  if (settings.backend.backend == Backend::Vulkan && a.lpv && !a.ddgi) {
    BackendChoice early;  // a missing device fails before the import (with --ddgi: the warm-up's start)
    GIBAKE_TRY(resolve_backend(settings.backend, early));
  }
  return Status::ok();
}

Status run_stages(const BakeArgs& a, const DdgiSettings& settings, const Context& ctx, BakeRun& run) {
  RunContext shared;  // what the DDGI bake is handed instead of building it
  if (a.ddgi && settings.backend.backend != Backend::Cpu) {
    // The driver opens the device while the scene is imported; no device fails here, before the import.
    GIBAKE_TRY(run.vulkan_warmup.start(settings.backend));
    shared.vulkan_warmup = &run.vulkan_warmup;
  }
  const auto t_import = Clock::now();
  GIBAKE_TRY(import_scene(a.scene, ImportOptions{}, ctx, run.scene));
  run.timings.emplace_back("import", seconds_since(t_import));
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
    if (run.shard_run.out) shared.shard = &run.shard_run;
    GIBAKE_TRY(bake_ddgi(run.scene, settings, shared, ctx, run.ddgi, run.ddgi_report));
    for (const auto& st : run.ddgi_report.stage_seconds) run.timings.push_back(st);
    if (!run.prepared) run.prepared = std::move(setup.prepared);
    run.lod = std::move(setup.lod);
    run.gpu = std::move(setup.gpu);
    if (!run.have_voxels) {
      run.voxels = std::move(setup.voxels);
      run.have_voxels = !run.voxels.empty();
    }
    // The leak warnings weigh the final probe states, which a shard does not have (the merge makes them).
    if (run.have_voxels && a.leak_audit == "on" && !run.shard_run.out) GIBAKE_TRY(run_leak_audit(settings, ctx, run));
  }
  if (a.lpv && (!run.shard_run.out || run.shard_run.range.index == 0)) {
    // A shard's LPV is the CPU's whatever auto chose for its probes (the merge copies it as it is).
    GIBAKE_TRY(bake_lpv(run.scene, *run.prepared, shade_lights(run.scene, settings.suns), &run.voxels,
                        to_lpv_settings(a, settings.backend), ctx, run.lpv, run.shard_run.out ? nullptr : &run.gpu));
    run.timings.emplace_back("lpv_vpls", run.lpv.stats.seconds_vpls);
    run.timings.emplace_back("lpv_propagate", run.lpv.stats.seconds_propagate);
  }
  if (a.vxgi.enabled) {
    GIBAKE_TRY(run_vxgi_stage(a.vxgi, settings, a.seed, a.blend_cutoff, run.scene, *run.prepared, ctx, run.vxgi));
    run.timings.emplace_back("vxgi_radiance", run.vxgi.stats.seconds_radiance);
    run.timings.emplace_back("vxgi_mips", run.vxgi.stats.seconds_mips);
  }
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

  BakeRun run;
  if (!a.shard.empty()) {
    parse_shard(a.shard, run.shard_run.range.index, run.shard_run.range.count);  // checked by check_args
    run.shard_run.out = &run.shard;
  }
  if (Status st = run_stages(a, settings, ctx, run); !st) return fail(st);
  if (a.ddgi || a.lpv || a.vxgi.enabled) {
    if (Status st = write_outputs(a, run, ctx, file_options); !st) return fail(st);
    if (a.ddgi && a.shard.empty() && a.reconstruction_check == "on")  // a shard holds no volume yet
      if (Status st = run_reconstruction_check(a, settings, ctx, run); !st) return fail(st);
  } else if (!a.depfile.empty()) {
    if (Status st = write_depfile(a.depfile, a.voxels, run.scene.input_files); !st) return fail(st);
  }
  if (!a.report.empty()) {
    const auto t_report = Clock::now();
    ReportPageInputs page;
    page.page = a.report;
    page.scene_path = a.scene;
    page.bake_path = a.out;
    page.blend_cutoff = a.blend_cutoff;
    page.scene = &run.scene;
    page.result = &run.ddgi;
    page.report = &run.ddgi_report;
    page.timings = run.timings;
    page.bake_start = t0;
    page.warnings = *warnings;
    if (run.have_leak_audit) page.leak_regions = leak_region_lines(run.leaks, run.exposure);
    if (run.have_reconstruction) page.reconstruction = &run.reconstruction;
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
    summary.voxels_sizing = a.voxel_size > 0.f ? "--voxel-size"
                                               : std::to_string(a.voxel_res ? a.voxel_res : VoxelSettings{}.resolution) +
                                                     " across the scene's longest side (--voxel-res)";
  }
  if (a.ddgi) {
    summary.result = &run.ddgi;
    summary.report = &run.ddgi_report;
  }
  if (a.lpv && !run.lpv.cascades.empty()) summary.lpv = &run.lpv;
  if (run.have_leak_audit) {
    summary.leaks = &run.leaks;
    summary.leak_exposure = &run.exposure;
  }
  if (run.have_reconstruction) summary.reconstruction = &run.reconstruction;
  summary.timings = run.timings;
  if (a.ddgi) summary.backend = &run.gpu.choice;
  print_bake_summary(summary, progress->mode());
  if (a.vxgi.enabled) print_vxgi_summary(run.vxgi, progress->mode());
  return 0;
}

}  // namespace

void add_bake_command(CLI::App& app, CliState& state) {
  auto args = std::make_shared<BakeArgs>();
  CLI::App* sub = app.add_subcommand("bake", "bake global illumination for a glTF scene");
  sub->add_option("scene", args->scene, "scene file (.gltf or .glb)")->required();
  sub->add_flag("--ddgi", args->ddgi, "bake DDGI probes");
  sub->add_option("--out,-o", args->out, "output bake file (with --ddgi and/or --lpv)");
  sub->add_flag("--lpv", args->lpv, "bake light propagation volume cascades into the bake file");
  sub->add_option("--voxels", args->voxels,
                  "voxelize the scene into this OpenVDB file (density, albedo, emission, normal, direct, aniso_*, "
                  "sdf, interior grids)");
  sub->add_option("--voxel-size", args->voxel_size, "voxel edge in metres (default: from --voxel-res)");
  sub->add_option("--voxel-res", args->voxel_res,
                  "voxels across the scene's longest side (default 128); the grid adds one empty voxel on every "
                  "side and one spare, so 128 gives 131 on that axis")
      ->check(whole_number(1, 1 << 20));
  sub->add_option("--voxel-sdf", args->voxel_sdf, "on|off: signed distance field grid 'sdf' (default on)");
  add_threads_option(sub, args->threads, "results");
  sub->add_option("--progress", args->progress, "auto|bar|lines|json (stderr)");
  sub->add_option("--probe-spacing", args->probe_spacing,
                  "probe spacing in metres (default: longest side / 16, within 0.25..4 m, at most 32768 probes)")
      ->check(positive_number());
  sub->add_option("--probe-counts", args->probe_counts, "X,Y,Z probes per axis");
  sub->add_option("--grid-min", args->grid_min, "x,y,z of probe (0,0,0) (with --grid-max, --probe-counts)");
  sub->add_option("--grid-max", args->grid_max, "x,y,z of the last probe");
  sub->add_option("--grid-padding", args->padding, "metres added around the scene bounds (default 0)");
  sub->add_option("--max-probes", args->max_probes, "refuse grids with more probes (default 2097152)")
      ->check(whole_number(0, INT64_MAX));
  sub->add_option("--rays", args->rays, "rays per probe per batch (default 256)")->check(whole_number(1, 1 << 20));
  sub->add_option("--max-rays", args->max_rays, "per-probe ray cap with --target-error (default 16 x --rays)")
      ->check(whole_number(0, 1 << 24));
  sub->add_option("--target-error", args->target_error, "stop a probe at this relative standard error");
  sub->add_option("--seed", args->seed, "random seed (default 0)")->check(unsigned_integer());
  sub->add_option("--gather", args->gather,
                  "path|probes: light at ray hits from continued paths (converges to the path-traced truth) or "
                  "read back from the previous pass's probes (fast runtime approximation) (default path)");
  sub->add_option("--backend", args->backend,
                  "auto|cpu|vulkan (default cpu): auto takes a discrete or integrated GPU when there is one; "
                  "vulkan demands a device (exit 4 without)");
  sub->add_option("--vulkan-device", args->vulkan_device,
                  "index or name from 'gibake info --devices', or lavapipe (Mesa's CPU device, only when named)");
  sub->add_option("--bounces", args->bounces, "indirect bounces: path vertices after the first hit (default 4)")
      ->check(whole_number(0, 64));
  sub->add_option("--energy-conservation", args->energy_conservation, "indirect scale per bounce (default 1)");
  sub->add_option("--sh-order", args->sh_order, "1 or 2 (default 2)");
  sub->add_option("--light-sampling", args->light_sampling, "all|random (default all)");
  sub->add_option("--sky", args->sky, "constant sky radiance r,g,b in cd/m^2 (default black)");
  sub->add_option("--sky-hdr", args->sky_hdr, "equirect EXR sky (+Y up, centre column looks along -Z)");
  sub->add_option("--sky-hdr-scale", args->sky_hdr_scale, "multiplier for --sky-hdr values (default 1)");
  sub->add_option("--sun", args->suns,
                  "directional light dx,dy,dz:lux[:r,g,b]; d is the direction the light travels (0,-1,0 = from "
                  "straight above); repeatable");
  sub->add_option("--relocate", args->relocate, "on|off (default on)");
  sub->add_option("--closed-mesh-check", args->closed_mesh_check,
                  "on|off: cross-check inactive probes against closed meshes with CGAL (default on)");
  sub->add_option("--blend-cutoff", args->blend_cutoff,
                  "alpha cutoff for alphaMode BLEND materials, which are traced as MASK (default 0.5; 0 = opaque)");
  sub->add_option("--max-atlas-width", args->max_atlas_width,
                  "widest atlas in texels; Y-planes of tiles wrap onto more rows to stay within it (default 16384)");
  sub->add_option("--depfile", args->depfile,
                  "also write a Makefile-style depfile listing the scene and every buffer/image read");
  sub->add_flag("--metadata-timings", args->metadata_timings,
                "record timings and the thread count in the file's metadata (the file then differs "
                "from run to run)");
  sub->add_option("--sh-format", args->sh_format, "f32|f16|auto: SH coefficient storage (default f32)");
  sub->add_option("--atlas-format", args->atlas_format,
                  "auto|f16|f32: atlas storage; auto = f16 when every value fits (default auto)");
  sub->add_option(
      "--leak-audit", args->leak_audit,
      "on|off: warn where a wall thinner than the probe spacing separates lit from unlit space (default on)");
  sub->add_option("--reconstruction-check", args->reconstruction_check,
                  "on|off: after a DDGI bake, compare the irradiance the loader's sampler reconstructs at surface "
                  "points with path-traced references and print the error (default on)");
  sub->add_option("--check-patches", args->check_patches, "4x4-point patches of the reconstruction check (default 128)")
      ->check(CLI::Range(1u, 1u << 20));
  sub->add_option("--check-rays", args->check_rays, "reference paths per point of the check (default 128)")
      ->check(CLI::Range(1u, 1u << 16));
  sub->add_option("--report", args->report,
                  "also write a self-contained HTML report (settings, timings, probe statistics, warnings, previews)");
  sub->add_option("--shard", args->shard,
                  "I/N: bake only shard I (from 0) of N of the probes into a shard file, for 'gibake merge'");
  sub->add_option("--lpv-res", args->lpv_res, "LPV cells on the longest axis of each cascade (default 32)");
  sub->add_option("--lpv-iterations", args->lpv_iterations,
                  "LPV propagation steps (default 0: the grid's longest axis)");
  sub->add_option("--lpv-cascades", args->lpv_cascades,
                  "nested LPV cascades, each twice the extent of the one inside it (default 1)");
  sub->add_option("--lpv-samples", args->lpv_samples,
                  "VPL rays per light, and VPLs on emissive triangles (default 65536)")
      ->check(whole_number(0, 0xffffffffLL));
  add_vxgi_options(sub, args->vxgi);
  sub->callback([&state, args] { state.run = [args] { return run_bake(*args); }; });
}

}  // namespace gibake::cli
