// The stages of a bake request in their order; each reads the request and leaves its results in
// the BakeResult the files are written from.
#include "bake/pipeline/stages.h"

#include <future>

#include "bake/lpv/lpv_device.h"
#include "bake/pipeline/check_refine.h"
#include "bake/pipeline/devices.h"
#include "bake/pipeline/shard_finish.h"
#include "bake/pipeline/surface_fit_stage.h"
#include "bake/run/bake_setup.h"
#include "bake/scene/lights.h"
#include "bake/scene/sky.h"
#include "bake/voxel/leak_warnings.h"
#include "io/export/voxels_vdb.h"
#include "io/gltf/import.h"
#include "io/timer.h"

namespace gibake {
namespace {

// The views' cameras, once the scene is known (`option` names them in errors).
Status resolve_views(const Scene& scene, const std::vector<CheckView>& views, const char* option,
                     std::vector<PreviewCamera>& out) {
  out.clear();
  for (const CheckView& view : views) {
    const PreviewSettings& s = view.settings;
    if (!s.camera_given && view.spec != "default" && s.camera_index >= scene.cameras.size())
      return Status::error(ExitCode::BadArguments, "", option,
                           view.spec + ": the scene has " + std::to_string(scene.cameras.size()) + " glTF camera(s)");
    PreviewCamera cam;
    std::string described;
    GIBAKE_TRY(resolve_camera(scene, s, cam, described));
    out.push_back(cam);
  }
  return Status::ok();
}

// The voxelize stage (for --voxels, and as the LPV's geometry volume): the scene's lights and the
// suns fill the direct channel.
Status run_voxels(const BakeRequest& r, const Context& ctx, BakeResult& run) {
  const auto t0 = Clock::now();
  GIBAKE_TRY(voxelize(run.scene, r.voxels, shade_lights(run.scene, r.ddgi_settings.suns), run.prepared.get(), ctx,
                      run.voxels, &run.voxel_report));
  run.have_voxels = true;
  run.timings.emplace_back("voxelize", seconds_since(t0));
  return Status::ok();
}

// The .vdb, written after the stages: with voxel GI it also holds the voxel-GI grids.
Status write_voxels_file(const BakeRequest& r, BakeResult& run) {
  const auto t_write = Clock::now();
  const VoxelVdbOptions options{voxel_settings_json(r.voxels), r.files.scene, run.scene.input_files};
  GIBAKE_TRY(write_voxels_vdb(r.files.voxels_out, run.voxels, vxgi_vdb_grids(run.vxgi), options));  // none without vxgi
  run.timings.emplace_back("write_vdb", seconds_since(t_write));
  return Status::ok();
}

// Voxel GI with the DDGI settings' lights and sky.
Status run_vxgi(const BakeRequest& r, const Context& ctx, BakeResult& run) {
  const DdgiSettings& ddgi = r.ddgi_settings;
  Sky sky;
  sky.constant = {ddgi.sky[0], ddgi.sky[1], ddgi.sky[2]};
  if (!ddgi.sky_hdr.empty()) {
    GIBAKE_TRY(load_sky_exr(ddgi.sky_hdr, sky));
    sky.scale = ddgi.sky_hdr_scale;
  }
  GIBAKE_TRY(bake_vxgi(run.scene, *run.prepared, shade_lights(run.scene, ddgi.suns), sky, r.vxgi_settings, ctx, run.vxgi));
  run.timings.emplace_back("vxgi_radiance", run.vxgi.stats.seconds_radiance);
  run.timings.emplace_back("vxgi_mips", run.vxgi.stats.seconds_mips);
  return Status::ok();
}

// The import, with the device warm-up beside it; the input hash and the file stream begun after it.
Status run_import(const BakeRequest& r, const Context& ctx, RunContext& shared, BakeResult& run) {
  if (r.ddgi && r.ddgi_settings.backend.backend != Backend::Cpu) {
    // The driver lists the devices and opens one while the scene is imported.
    GIBAKE_TRY(run.vulkan_warmup.start(r.ddgi_settings.backend));
    shared.vulkan_warmup = &run.vulkan_warmup;
  }
  const auto t_import = Clock::now();
  ImportOptions import_options;
  // The driver lists the devices while the scene imports: a missing device stops the import and its
  // error (exit 4) is the one reported. A listing still under way is waited for by the set-up, which
  // reports the same error before it builds anything for the device.
  if (shared.vulkan_warmup) import_options.cancelled = [&run] { return run.vulkan_warmup.listing_failed(); };
  const Status imported = import_scene(r.files.scene, import_options, ctx, run.scene);
  if (shared.vulkan_warmup && run.vulkan_warmup.listing_failed()) GIBAKE_TRY(run.vulkan_warmup.listed());
  GIBAKE_TRY(imported);
  if ((r.ddgi || r.lpv || r.vxgi) && !any_triangle_has_area(run.scene))
    return Status::invalid(r.files.scene, "scene",
                           "no triangle has an area (every one is a point or a line): nothing to light or place "
                           "probes by");
  run.timings.emplace_back("import", seconds_since(t_import));
  // A whole DDGI bake's file is begun before the trace, its atlases written as their rows become
  // final (io/bakefile/bake_stream.h); the write after the bake adopts them or starts afresh.
  // The stream predicts a file of DDGI alone: none beside LPV or voxel GI sections, nor for a shard.
  // Refinement by check adds volumes after the bake and the surface fit changes the atlases, so
  // their files are written afterwards.
  // The stream encodes float16 or float32 rows, not RGB9E5.
  if (r.ddgi && !r.lpv && !r.vxgi && !run.shard_run.volumes_out && r.volumes.check_budget == 0 &&
      !r.ddgi_settings.fit.enabled && r.file_options.atlas != FloatPrecision::SharedExponent) {
    run.file_stream = std::make_unique<BakeFileStream>(r.files.out, run.scene.input_files, r.file_options);
    shared.file_stream = run.file_stream.get();
  }
  run.input_digest = std::async(std::launch::async, [&scene = run.scene] {
                       InputDigest digest = digest_scene(scene);
                       Status st = digest_files(scene.input_files, digest);
                       return std::make_pair(std::move(st), std::move(digest));
                     }).share();  // read twice by a --from-shards run: its parts' check and the write
  std::vector<PreviewCamera> near;
  GIBAKE_TRY(resolve_views(run.scene, r.near_views, "--near-camera", near));
  for (size_t i = 0; i < near.size(); ++i) {
    const PreviewCamera& c = near[i];
    run.volume_settings.views.push_back({r.near_views[i].spec, c.eye, c.forward, c.right, c.up, c.tan_half, c.aspect});
  }
  return resolve_views(run.scene, r.check.views, "--check-camera", run.check_cameras);
}

// The DDGI volumes. The bake builds what it needs before its first ray (bake/pipeline/bake_setup.h: the
// BVH, mips and enclosure grid side by side, with its closed-mesh check already running beside them)
// and leaves it in `setup`, so that the leak audit reads the enclosure grid too.
Status run_ddgi(const BakeRequest& r, const Context& ctx, RunContext& shared, BakeResult& run) {
  BakeSetup setup;
  const PipelineDevices platform;  // the set-up and the device: the backend is chosen there
  shared.platform = &platform;
  shared.closed_meshes = &run.closed_meshes;
  if (run.have_voxels) shared.voxels = &run.voxels;
  shared.prepared = run.prepared.get();
  shared.setup_out = &setup;
  if (run.shard_run.volumes_out) shared.shard = &run.shard_run;
  GIBAKE_TRY(bake_ddgi_volumes(run.scene, r.ddgi_settings, run.volume_settings, shared, ctx, run.volumes,
                               &run.volume_rule, &run.refine_rule));
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
  if (!r.from_shards.empty()) GIBAKE_TRY(take_volumes_from_shards(r, ctx, shared, run));
  GIBAKE_TRY(refine_by_check(r, ctx, shared, run));
  GIBAKE_TRY(fit_surfaces(r, ctx, run));
  if (leak_audit_wanted(r, run) && !leak_audit_beside_write(r)) {
    double seconds = 0.0;
    GIBAKE_TRY(run_leak_audit(r, ctx, run, seconds));
    if (run.have_leak_audit) run.timings.emplace_back("leak audit", seconds);
  }
  return Status::ok();
}

// The LPV runs on the DDGI bake's device session when it has one (one Vulkan context a process). A
// shard's LPV is the CPU's whatever auto chose for its probes (the merge copies it as it is).
Status run_lpv(const BakeRequest& r, const Context& ctx, BakeResult& run) {
  BackendChoice choice;
  std::unique_ptr<LpvDevice> device;
  GIBAKE_TRY(make_lpv_device(r.lpv_settings.backend, run.shard_run.volumes_out ? nullptr : run.gpu.get(), ctx, device,
                             choice));
  GIBAKE_TRY(bake_lpv(run.scene, *run.prepared, shade_lights(run.scene, r.ddgi_settings.suns), &run.voxels,
                      r.lpv_settings, ctx, run.lpv, std::move(device), choice));
  run.timings.emplace_back("lpv_vpls", run.lpv.stats.seconds_vpls);
  run.timings.emplace_back("lpv_propagate", run.lpv.stats.seconds_propagate);
  return Status::ok();
}

}  // namespace

Status run_leak_audit(const BakeRequest& r, const Context& ctx, BakeResult& run, double& seconds) {
  const Stopwatch audit_time;
  GIBAKE_TRY(audit_bake_leaks(run.voxels, *run.prepared, shade_lights(run.scene, r.ddgi_settings.suns), run.ddgi(),
                              ctx, run.leaks, run.exposure, run.have_leak_audit));
  seconds = audit_time.seconds();
  return Status::ok();
}

bool leak_audit_wanted(const BakeRequest& r, const BakeResult& run) {
  return r.ddgi && run.have_voxels && r.leak_audit && !run.shard_run.volumes_out;
}

Status run_bake_stages(const BakeRequest& r, const Context& ctx, BakeResult& run) {
  RunContext shared;  // what the DDGI bake is handed instead of building it
  GIBAKE_TRY(run_import(r, ctx, shared, run));
  if (r.vxgi) {  // the voxel GI grid's size and memory are judged before any stage spends time
    VoxelGrid layout;
    uint64_t estimate = 0;
    GIBAKE_TRY(plan_vxgi(run.scene, r.vxgi_settings, layout, estimate));
  }
  // One Embree scene and one voxel grid for every stage.
  const bool full_voxels = !r.files.voxels_out.empty() || r.lpv;
  if (full_voxels || !r.ddgi) {
    const auto t_prepare = Clock::now();
    PrepareOptions options;
    options.blend_cutoff = r.ddgi_settings.blend_cutoff;
    GIBAKE_TRY(PreparedScene::create(run.scene, ctx, run.prepared, options));
    run.timings.emplace_back("prepare", seconds_since(t_prepare));
  }
  if (full_voxels) GIBAKE_TRY(run_voxels(r, ctx, run));
  if (r.ddgi) GIBAKE_TRY(run_ddgi(r, ctx, shared, run));
  if (r.lpv && (!run.shard_run.volumes_out || run.shard_run.range.index == 0)) GIBAKE_TRY(run_lpv(r, ctx, run));
  if (r.vxgi) GIBAKE_TRY(run_vxgi(r, ctx, run));
  if (!r.files.voxels_out.empty()) GIBAKE_TRY(write_voxels_file(r, run));
  return Status::ok();
}

}  // namespace gibake
