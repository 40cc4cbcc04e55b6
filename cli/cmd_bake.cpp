// `gibake bake scene.gltf [--ddgi] [--lpv] [--vxgi] [--out F] [--voxels F.vdb] [options]` (the
// subcommand is implied): the arguments become a BakeRequest (settings in bake_args.cpp, checked
// here before any work), the library runs it (bake/pipeline/bake_request.h), and the summary
// (bake_summary.cpp) and --report page are printed from what it hands back.

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/volumes.h"
#include "bake/pipeline/bake_request.h"
#include "bake/run/arena.h"
#include "bake/scene/sky.h"
#include "bake/voxel/leak_warnings.h"
#include "bake/voxel/voxelize.h"
#include "bake/vxgi/vxgi.h"
#include "cli/bake_args.h"
#include "cli/bake_report_page.h"
#include "cli/bake_summary.h"
#include "cli/check_camera.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "io/bakefile/bake_file.h"
#include "io/gltf/scene_inputs.h"
#include "io/output/depfile.h"
#include "io/output/output_check.h"
#include "io/timer.h"

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
// at once rather than piece by piece on the way out, as compilers do (clang's -disable-free). Under AddressSanitizer it returns,
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

// A depfile's rule names the output and every input: a path no Makefile rule can hold is refused
// before the bake, not found when the depfile is written after it.
Status check_depfile_paths(const BakeArgs& a, const std::vector<NamedPath>& inputs) {
  if (a.depfile.empty()) return Status::ok();
  std::vector<NamedPath> named;  // as the depfile writes them: the inputs absolute, the target as given
  for (const NamedPath& p : inputs) named.push_back({p.option, depfile_input_path(p.path)});
  const bool bake_file = a.ddgi || a.lpv || a.vxgi.enabled;  // the depfile's target: the bake file, else the .vdb
  named.push_back({bake_file ? "--out" : "--voxels", bake_file ? a.out : a.voxels});
  for (const NamedPath& p : named)
    if (const char c = depfile_unwritable(p.path))
      return bad_arg("--depfile", p.option + " '" + p.path + "' holds " + depfile_char_name(c) +
                                      ", which a Makefile rule cannot hold: rename it, or leave out --depfile");
  return Status::ok();
}

// Every file the bake will write, against each other and against every file it reads (the scene,
// its buffers and images from a pre-read of its JSON, the sky HDR): refused before any work.
Status check_bake_paths(const BakeArgs& a) {
  std::vector<NamedPath> outputs;
  if (a.ddgi || a.lpv || a.vxgi.enabled) outputs.push_back({"--out", a.out});
  if (!a.voxels.empty()) outputs.push_back({"--voxels", a.voxels});
  if (!a.report.empty()) outputs.push_back({"--report", a.report});
  if (!a.depfile.empty()) outputs.push_back({"--depfile", a.depfile});
  std::vector<NamedPath> inputs = scene_input_files(a.scene);
  if (!a.sky_hdr.empty()) inputs.push_back({"--sky-hdr", a.sky_hdr});
  for (const std::string& part : a.from_shards) inputs.push_back({"--from-shards", part});
  GIBAKE_TRY(check_output_paths(outputs, inputs));
  return check_depfile_paths(a, inputs);
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
  if (a.vxgi.enabled)
    return bad_arg("--shard", "voxel GI is not carried by shards: bake --vxgi once without --shard, in its own file");
  return Status::ok();
}

// --from-shards PART...: the shards' own command line finishes a bake whose last stages read the
// scene (refinement by check, the surface fit).
Status check_from_shards_args(const BakeArgs& a, const DdgiSettings& settings) {
  if (!a.shard.empty())
    return bad_arg("--from-shards", "finishes the bake the shards split: give it in place of --shard, not with it");
  if (a.vxgi.enabled)
    return bad_arg("--from-shards",
                   "voxel GI is not carried by shards: bake --vxgi once without them, in its own file");
  if (!a.ddgi || (a.refine_by_check == 0 && !settings.fit.enabled))
    return bad_arg("--from-shards",
                   "finishes a --ddgi bake that refines by check (--refine-by-check N) or fits its atlases to the "
                   "surfaces (--surface-fit on); 'gibake merge' finishes the others");
  return Status::ok();
}

// Every check that needs no scene, so that a typo fails before a long import.
Status check_args(const BakeArgs& a, ProgressMode& mode, DdgiSettings& settings, BakeFileOptions& file_options) {
  GIBAKE_TRY(refuse_bake_file_as_scene(a.scene));  // the mistake behind every other message
  // --from-shards takes every word after it: an option there was meant as an option.
  for (const std::string& part : a.from_shards)
    if (part.size() > 2 && part.compare(0, 2, "--") == 0)
      return bad_arg("--from-shards", "takes the shard files, got the option " + part +
                                          ": give the parts after the other options, or --from-shards last");
  const bool bake_file = a.ddgi || a.lpv || a.vxgi.enabled;
  if (!bake_file && a.voxels.empty())
    return bad_arg("bake", "nothing to bake: add --ddgi, --lpv, --vxgi and/or --voxels (e.g. gibake " +
                               (a.scene.empty() ? std::string("scene.gltf") : a.scene) +
                               " --ddgi --out probes.gibake)");
  if (bake_file && a.out.empty()) return bad_arg("--out", "an output file is required (--out probes.gibake)");
  if (bake_file) GIBAKE_TRY(check_bake_file_name("--out", a.out));
  // Each output named as another kind of file (`--voxels v.png`, `--depfile scene.gltf`) is a typo
  // that would write over what the name promises; names of no known kind are taken as given.
  if (!a.voxels.empty()) GIBAKE_TRY(check_output_kind("--voxels", a.voxels, {".vdb"}, "an OpenVDB file"));
  if (!a.report.empty()) GIBAKE_TRY(check_output_kind("--report", a.report, {".html", ".htm"}, "a web page"));
  if (!a.depfile.empty()) GIBAKE_TRY(check_output_kind("--depfile", a.depfile, {".d", ".txt"}, "a Makefile depfile"));
  if (!bake_file && !a.out.empty())
    return bad_arg("--out", "--out names the bake file of --ddgi/--lpv; --voxels names its own file");
  GIBAKE_TRY(parse_progress_option(a.progress, mode));
  GIBAKE_TRY(to_settings(a, settings));
  VolumeSettings volume_check;
  GIBAKE_TRY(to_volume_settings(a, volume_check));
  GIBAKE_TRY(check_refine_ray_budget(a, settings, volume_check));
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
  GIBAKE_TRY(check_camera_specs(a.near_cameras, a.near_fov, "--near-camera", "--near-fov"));
  if (!a.near_cameras.empty() && !a.ddgi) return bad_arg("--near-camera", "places probes for a probe bake: add --ddgi");
  if (!a.report.empty() && !a.ddgi) return bad_arg("--report", "the report describes a probe bake: add --ddgi");
  if (!parse_precision(a.sh_format, file_options.sh) || file_options.sh == FloatPrecision::SharedExponent)
    return bad_arg("--sh-format", "expected f32, f16 or auto, got '" + a.sh_format + "'");
  if (!parse_precision(a.atlas_format, file_options.atlas))
    return bad_arg("--atlas-format", "expected auto, f16, f32 or rgb9e5, got '" + a.atlas_format + "'");
  GIBAKE_TRY(check_bake_paths(a));
  if (!a.shard.empty()) GIBAKE_TRY(check_shard_args(a, settings));
  if (!a.from_shards.empty()) GIBAKE_TRY(check_from_shards_args(a, settings));
  if (settings.backend.backend == Backend::Vulkan && a.lpv && !a.ddgi) {
    BackendChoice early;  // a missing device fails before the import (with --ddgi: the warm-up's start)
    GIBAKE_TRY(resolve_backend(settings.backend, early));
  }
  return Status::ok();
}

// The request the arguments make (check_args has checked every one of them).
BakeRequest make_request(const BakeArgs& a, const DdgiSettings& settings, const BakeFileOptions& file_options) {
  BakeRequest r;
  r.files = {a.scene, a.out, a.voxels, a.depfile};
  r.ddgi = a.ddgi;
  r.lpv = a.lpv;
  r.vxgi = a.vxgi.enabled;
  r.ddgi_settings = settings;
  to_volume_settings(a, r.volumes);
  to_voxel_settings(a, r.voxels);
  r.lpv_settings = to_lpv_settings(a, settings.backend);
  if (r.vxgi) to_vxgi_settings(a.vxgi, a.seed, a.blend_cutoff, r.vxgi_settings);
  r.file_options = file_options;
  r.threads = a.threads;
  r.metadata_timings = a.metadata_timings;
  r.leak_audit = a.leak_audit == "on";
  r.check = {a.reconstruction_check == "on",
             a.check_patches,
             a.check_rays,
             a.check_noise,
             a.check_ray_budget,
             {},
             kCheckWidth,
             kCheckHeight};
  for (const std::string& spec : a.check_cameras) {
    CheckView view{spec, {}};
    check_view_settings(spec, a.check_fov, view.settings);
    r.check.views.push_back(std::move(view));
  }
  for (const std::string& spec : a.near_cameras) {
    CheckView view{spec, {}};
    check_view_settings(spec, a.near_fov, view.settings, "--near-camera");
    r.near_views.push_back(std::move(view));
  }
  if (!a.shard.empty()) {
    r.shard = true;
    parse_shard(a.shard, r.shard_index, r.shard_count);
  }
  r.from_shards = a.from_shards;
  return r;
}

// The HTML report (--report), timed into the run's timings.
Status write_report(const BakeArgs& a, const DdgiSettings& settings, const std::vector<std::string>& warnings,
                    Clock::time_point bake_start, const Context& ctx, BakeResult& run) {
  const auto t_report = Clock::now();
  ReportPageInputs page;
  page.page = a.report;
  page.scene_path = a.scene;
  page.bake_path = a.out;
  page.blend_cutoff = a.blend_cutoff;
  page.scene = &run.scene;
  page.result = &run.ddgi();
  page.report = &run.ddgi_report();
  page.volumes = &run.volumes;
  page.timings = run.timings;
  page.bake_start = bake_start;
  page.warnings = warnings;
  if (run.have_leak_audit) page.leak_regions = leak_region_lines(run.leaks, run.exposure);
  if (run.have_reconstruction) page.reconstruction = &run.reconstruction;
  if (!a.check_cameras.empty()) {
    page.view = a.check_cameras.front();
    page.view_fov = a.check_fov;
  }
  if (run.list_volumes()) page.volumes_json = volumes_json(run.volumes);
  page.quality = quality_summary(a, settings, run.volume_settings, run.ddgi().desc.spacing[0]);
  GIBAKE_TRY(write_report_page(page, ctx));
  run.timings.emplace_back("report", seconds_since(t_report));
  return Status::ok();
}

// What the summary prints of the run (pointers into `run`, which outlives it).
BakeSummary bake_summary(const BakeArgs& a, const DdgiSettings& settings, const BakeResult& run) {
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
    summary.refine_rule = run.refine_rule;
    summary.quality = quality_summary(a, settings, run.volume_settings, run.ddgi().desc.spacing[0]);
  }
  if (a.lpv && !run.lpv.cascades.empty()) summary.lpv = &run.lpv;
  if (run.have_leak_audit) {
    summary.leaks = &run.leaks;
    summary.leak_exposure = &run.exposure;
  }
  if (run.have_reconstruction) summary.reconstruction = &run.reconstruction;
  summary.timings = run.timings;
  if (a.ddgi && run.had_session) summary.backend = &run.backend;
  return summary;
}

// --sky-hdr read before the import: a map the bake cannot read is refused before any work, and
// one with values it reads as 0 (NaN, infinite, negative) is reported once. The bake reads it again.
Status check_sky_map(const BakeArgs& a, const Context& ctx) {
  if (a.sky_hdr.empty()) return Status::ok();
  Sky sky;
  GIBAKE_TRY(load_sky_exr(a.sky_hdr, sky));
  if (sky.replaced_values > 0)
    ctx.warning(a.sky_hdr + ": " + std::to_string(sky.replaced_values) +
                " value(s) NaN, infinite or negative read as 0: the sky lights the scene less than the map says");
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
  if (Status st = check_sky_map(a, ctx); !st) return fail(st);
  // On the heap, so that its memory can go back beside the device's close at the end.
  std::unique_ptr<BakeResult> run_memory;
  if (Status st = gibake::run_bake(make_request(a, settings, file_options), ctx, run_memory); !st) return fail(st);
  BakeResult& run = *run_memory;
  if (!a.report.empty()) {
    if (Status st = write_report(a, settings, *warnings, t0, ctx, run); !st) return fail(st);
  }
  run.timings.emplace_back("total", seconds_since(t0));

  progress->clear();
  print_bake_summary(bake_summary(a, settings, run), progress->mode());
  if (a.vxgi.enabled) print_vxgi_summary(run.vxgi, progress->mode());
  // The bake's host memory (scene, BVH, mips, voxels, results) goes back beside the device's close,
  // which the process waits for anyway, rather than in the process's exit after it. Freeing the
  // result joins the session's close: no driver call is cut short.
  ReleaseBeside freeing;
  freeing.release(std::move(run_memory));
  freeing.wait();
  end_process_without_teardown(0);
  return 0;
}

}  // namespace

const Command kBakeCommand{"bake", add_command<BakeArgs, add_bake_options, run_bake>};

}  // namespace gibake::cli
