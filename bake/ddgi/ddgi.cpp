#include "bake/ddgi/ddgi.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <nlohmann/json.hpp>

#include "bake/ddgi/bounce.h"
#include "bake/ddgi/classify.h"
#include "bake/ddgi/probe_integrate.h"
#include "bake/ddgi/relocate_stage.h"
#include "bake/ddgi/shard_bake.h"
#include "bake/ddgi/trace_stage.h"
#include "bake/run/arena.h"
#include "bake/run/bake_setup.h"
#include "bake/run/probe_loop.h"
#include "bake/scene/emitters.h"
#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/scene/sky.h"
#include "bake/trace/path_gather.h"
#include "bake/trace/probe_rays.h"
#include "bake/voxel/voxelize.h"
#include "bake/vulkan/bounce.h"
#include "bake/vulkan/path.h"
#include "bake/vulkan/session.h"
#include "kernels/ddgi_sample.h"
#include "kernels/integrate.h"
#include "kernels/octahedral.h"
#include "kernels/ray_gen.h"
#include "kernels/sh.h"

namespace gibake {
using kernels::float3;
using kernels::HitRecord;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "ddgi", what); }

// What the bounce passes read: the grid, the probes' offsets and states, depth tiles, pass-0
// results and bouncing hits (positions are set by the caller). No passes for the path gather.
BounceInputs bounce_inputs(const DdgiVolumeDesc& desc, const DdgiSettings& s, const std::vector<float>& offsets,
                           const ProbeIntegrator& integ, const DdgiResult& result) {
  BounceInputs bi;
  for (int a = 0; a < 3; ++a) {
    bi.volume.grid_min[a] = desc.grid_min[a];
    bi.volume.spacing[a] = desc.spacing[a];
    bi.volume.counts[a] = desc.counts[a];
  }
  bi.volume.params[0] = s.normal_bias;
  bi.volume.params[1] = s.smooth_backface;
  bi.volume.offsets = offsets.data();
  bi.volume.inactive = integ.inactive.data();
  bi.volume.depth_atlas = result.depth_atlas.data();
  bi.volume.depth_tiles = integ.depth_tiles.data();
  bi.volume.depth_width = result.depth_width;
  bi.volume.atlas_planes_per_row = result.atlas_planes_per_row;
  bi.volume.depth_res = kDepthTexels;
  bi.sh0 = &integ.sh0;
  bi.hits = &integ.bounce_hits;
  bi.probe_rays = integ.probe_rays.data();
  bi.texel_dirs = integ.texel_dirs().data();
  bi.sh_order = s.sh_order;
  bi.bounces = s.gather == Gather::Path ? 0 : s.bounces;
  bi.energy_conservation = s.energy_conservation;
  return bi;
}

// The one dispatch point of the bounce passes: on the device when `vk` is set (its kernel time
// goes to the bake's notes as "vulkan: ..."), else run_bounce_passes on the CPU in `arena`.
Status run_bounces(const BounceInputs& in, vk::Context* vk, tbb::task_arena& arena, const Context& ctx,
                   std::vector<float>& sh, std::vector<float>& irradiance, BounceTimes& times) {
  if (!vk || in.bounces == 0) {  // no passes (the path gather): pass 0's SH, nothing to upload
    run_bounce_passes(in, arena, ctx, sh, irradiance, times);
    return Status::ok();
  }
  const auto t0 = Clock::now();
  GpuBounceStats stats;
  // One submission for every pass: progress can only say it started and ended.
  ctx.report("bounces (vulkan)", 0.0, 1.0);
  GIBAKE_TRY(run_bounce_passes_gpu(*vk, in, sh, irradiance, stats));
  ctx.report("bounces (vulkan)", 1.0, 1.0);
  times.stage_seconds.emplace_back("bounces (vulkan)", seconds_since(t0));
  char line[256];
  std::snprintf(line, sizeof(line),
                "vulkan: bounce kernels %.3f s of device time (weights %.3f s, %d passes %.3f s), %u hit chunk(s), "
                "%u submission(s), %.1f MB of device memory",
                stats.weights_seconds + stats.pass_seconds, stats.weights_seconds, in.bounces, stats.pass_seconds,
                stats.chunks, stats.submissions, stats.device_bytes / 1e6);
  ctx.note(line);
  return Status::ok();
}

// The states come from the ray test alone (the integrator's inactive[] uses the same rule), so
// the closed-mesh check only feeds the report; its tester was built by `check` beside the earlier
// stages, and is waited for after the bounce passes. With `vk` the passes run on the device. The
// bounce hits are released afterwards.
Status classify_after_bounces(const DdgiSettings& s, const std::vector<float>& positions, const BounceInputs& bi,
                              vk::Context* vk, tbb::task_arena& arena, const Context& ctx, BesideTask& check,
                              const ClosedMeshCheck& closed_check, ProbeIntegrator& integ, DdgiResult& result,
                              ClassifyReport& cr, DdgiReport& report) {
  ray_test_states(result.stats, s.backface_threshold, result.states);
  BounceTimes bounce_times;
  const Status bounce_status = run_bounces(bi, vk, arena, ctx, result.sh, integ.irradiance, bounce_times);
  for (const auto& st : bounce_times.stage_seconds) report.stage_seconds.push_back(st);
  std::vector<std::vector<BounceHit>>().swap(integ.bounce_hits);
  GIBAKE_TRY(bounce_status);
  if (check.started()) {
    const double waited = check.wait();
    report.stage_seconds.emplace_back("closed-mesh check (task beside the stages)", check.seconds());
    report.stage_seconds.emplace_back("closed-mesh check wait", waited);
    const auto t0 = Clock::now();
    cr = closed_check.report(positions, result.stats, result.states);
    report.stage_seconds.emplace_back("closed-mesh check (solids, queries)", seconds_since(t0));
  }
  return Status::ok();
}

std::string grid_summary(const DdgiVolumeDesc& d, const GridSettings& g) {
  char text[320];
  const char* rule = g.counts[0] > 0 ? "--probe-counts" : g.spacing > 0.f ? "--probe-spacing" : "default spacing rule";
  std::snprintf(text, sizeof text,
                "probe grid %dx%dx%d = %d probes, spacing %.3g x %.3g x %.3g m, from (%.3g, %.3g, %.3g) to (%.3g, "
                "%.3g, %.3g) (%s)",
                d.counts[0], d.counts[1], d.counts[2], d.probe_count(), d.spacing[0], d.spacing[1], d.spacing[2],
                d.grid_min[0], d.grid_min[1], d.grid_min[2], d.grid_max[0], d.grid_max[1], d.grid_max[2], rule);
  return text;
}

}  // namespace

std::string ddgi_settings_json(const DdgiSettings& s, const BackendChoice* ran_on) {
  nlohmann::json j;
  if (ran_on && ran_on->backend == Backend::Vulkan) {
    j["backend"] = backend_name(Backend::Vulkan);
    j["vulkan_device"] = ran_on->device.name;
    j["vulkan_driver"] = ran_on->device.driver;
  }
  j["grid"] = {{"padding", s.grid.padding},
               {"spacing", s.grid.spacing},
               {"counts", s.grid.counts},
               {"explicit_bounds", s.grid.explicit_bounds},
               {"grid_min", s.grid.grid_min},
               {"grid_max", s.grid.grid_max},
               {"auto_cells", s.grid.auto_cells},
               {"auto_min_spacing", s.grid.auto_min_spacing},
               {"auto_max_spacing", s.grid.auto_max_spacing},
               {"auto_max_probes", s.grid.auto_max_probes},
               {"max_probes", s.grid.max_probes}};
  j["rays"] = s.rays;
  j["max_rays"] = s.max_rays;
  j["target_error"] = s.target_error;
  j["seed"] = s.seed;
  j["gather"] = s.gather == Gather::Path ? "path" : "probes";
  j["bounces"] = s.bounces;
  j["roulette_depth"] = s.roulette_depth;
  j["energy_conservation"] = s.energy_conservation;
  j["sh_order"] = s.sh_order;
  j["light_sampling"] = s.light_sampling == LightSampling::Random ? "random" : "all";
  j["sky"] = s.sky;
  j["sky_hdr"] = s.sky_hdr;
  j["sky_hdr_scale"] = s.sky_hdr_scale;
  nlohmann::json suns = nlohmann::json::array();
  for (const SunLight& sun : s.suns)
    suns.push_back({{"direction", sun.direction}, {"lux", sun.lux}, {"color", sun.color}});
  j["suns"] = suns;
  j["relocate"] = s.relocate;
  j["relocate_fraction"] = s.relocate_fraction;
  j["relocate_max_fraction"] = s.relocate_max_fraction;
  j["relocate_rays"] = s.relocate_rays;
  j["relocate_iterations"] = s.relocate_iterations;
  j["backface_threshold"] = s.backface_threshold;
  j["closed_mesh_check"] = s.cgal_check;
  j["blend_cutoff"] = s.blend_cutoff;
  j["enclosure_resolution"] = s.enclosure_resolution;
  j["max_atlas_width"] = s.max_atlas_width;
  j["normal_bias"] = s.normal_bias;
  j["smooth_backface"] = s.smooth_backface;
  j["max_distance"] = s.max_distance;
  return j.dump();
}

Status validate_ddgi_settings(const DdgiSettings& s) {
  if (s.rays < 1 || s.rays > (1u << 20)) return bad("--rays must be between 1 and 1048576");
  if (s.bounces < 0 || s.bounces > 64) return bad("--bounces must be between 0 and 64");
  if (s.roulette_depth < 0 || s.roulette_depth > 64) return bad("roulette depth must be between 0 and 64");
  if (s.enclosure_resolution < 0 || s.enclosure_resolution > 4096)
    return bad("enclosure voxel resolution must be between 0 and 4096");
  if (s.sh_order != 1 && s.sh_order != 2) return bad("--sh-order must be 1 or 2");
  if (!(s.energy_conservation >= 0.f && s.energy_conservation <= 1.f))
    return bad("--energy-conservation must be in [0, 1]");
  if (!(s.target_error >= 0.f)) return bad("--target-error must be non-negative");
  if (s.max_rays > (1u << 24)) return bad("--max-rays too large");
  for (float c : s.sky)
    if (!(c >= 0.f) || !std::isfinite(c)) return bad("--sky components must be finite and non-negative");
  for (const SunLight& sun : s.suns) {
    const float l = std::sqrt(sun.direction[0] * sun.direction[0] + sun.direction[1] * sun.direction[1] +
                              sun.direction[2] * sun.direction[2]);
    if (!(l > 0.f) || !std::isfinite(l)) return bad("--sun direction must be a non-zero vector");
    if (!(sun.lux >= 0.f) || !std::isfinite(sun.lux)) return bad("--sun illuminance must be non-negative");
  }
  if (!(s.relocate_fraction >= 0.f && s.relocate_fraction < 1.f)) return bad("relocation fraction out of range");
  if (!(s.backface_threshold > 0.f && s.backface_threshold <= 1.f)) return bad("back-face threshold out of range");
  if (!(s.blend_cutoff >= 0.f && s.blend_cutoff <= 1.f)) return bad("--blend-cutoff must be in [0, 1]");
  if (s.max_atlas_width < 18 || s.max_atlas_width > (1 << 20))
    return bad("--max-atlas-width must be between 18 and 1048576 texels");
  return Status::ok();
}

Status bake_ddgi(const Scene& scene, const DdgiSettings& s, const Context& ctx, DdgiResult& result,
                 DdgiReport& report) {
  const auto t_start = Clock::now();
  report = DdgiReport{};
  result = DdgiResult{};
  GIBAKE_TRY(validate_ddgi_settings(s));
  DdgiVolumeDesc& desc = result.desc;
  GIBAKE_TRY(place_probe_grid(scene, s.grid, desc));
  desc.sh_order = s.sh_order;
  const int32_t probe_count = desc.probe_count();
  ctx.note(grid_summary(desc, s.grid));
  const int coefs = desc.sh_coefficients();
  const bool adaptive = s.target_error > 0.f;
  const uint32_t max_rays = adaptive ? std::max(s.rays, s.max_rays ? s.max_rays : 16 * s.rays) : s.rays;

  kernels::AtlasLayout irr_layout, depth_layout;
  for (int a = 0; a < 3; ++a) irr_layout.counts[a] = depth_layout.counts[a] = desc.counts[a];
  irr_layout.res = kIrradianceTexels;
  depth_layout.res = kDepthTexels;
  // One layout for both atlases, chosen so the wider (depth) one fits max_atlas_width.
  result.atlas_planes_per_row =
      kernels::atlas_planes_per_row(desc.counts[0], desc.counts[1], depth_layout.tile(), s.max_atlas_width);
  irr_layout.planes_per_row = depth_layout.planes_per_row = result.atlas_planes_per_row;

  // Memory estimate: hit records for every probe, per-bounce SH/irradiance and the atlases.
  const double est =
      double(probe_count) *
          (double(max_rays) * sizeof(HitRecord) + 2.0 * coefs * 3 * 4 + kIrradianceTexels * kIrradianceTexels * 3 * 4) +
      double(irr_layout.width()) * irr_layout.height() * 16 + double(depth_layout.width()) * depth_layout.height() * 8;
  if (est > double(s.max_memory_bytes))
    return bad("the bake would need about " + std::to_string(static_cast<uint64_t>(est / (1 << 20))) +
               " MiB (over the cap of " + std::to_string(s.max_memory_bytes >> 20) + " MiB); use fewer probes or rays");

  // Miss depth: 1.5 x diagonal of the scene and grid bounds together.
  Bounds all = scene.bounds;
  all.extend({desc.grid_min[0], desc.grid_min[1], desc.grid_min[2]});
  all.extend({desc.grid_max[0], desc.grid_max[1], desc.grid_max[2]});
  const float diag = std::sqrt((all.max[0] - all.min[0]) * (all.max[0] - all.min[0]) +
                               (all.max[1] - all.min[1]) * (all.max[1] - all.min[1]) +
                               (all.max[2] - all.min[2]) * (all.max[2] - all.min[2]));
  desc.max_distance = s.max_distance > 0.f ? s.max_distance : std::max(1.5f * diag, 1.f);
  const float max_distance = desc.max_distance;

  Sky sky;
  sky.constant = {s.sky[0], s.sky[1], s.sky[2]};
  if (!s.sky_hdr.empty()) {
    GIBAKE_TRY(load_sky_exr(s.sky_hdr, sky));
    sky.scale = s.sky_hdr_scale;
  }

  const std::vector<kernels::ShadeLight> lights = shade_lights(scene, s.suns);

  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);

  // --- the closed-mesh check, a task beside every stage up to the classification (it needs no ray) ---
  ClosedMeshCheck closed_check;
  BesideTask check_task;  // declared after what it writes: destroyed (waited for) first
  std::vector<float> rest_positions;
  float reach[3] = {0.f, 0.f, 0.f};  // how far relocation may move a probe from its rest position
  if (s.cgal_check && scene.triangle_count() > 0) {
    rest_positions.resize(size_t(probe_count) * 3);
    for (int32_t p = 0; p < probe_count; ++p) {
      const auto rest = probe_rest_position(desc, p);
      for (int a = 0; a < 3; ++a) rest_positions[size_t(p) * 3 + a] = rest[a];
    }
    const float cell = min_cell_size(desc);
    if (s.relocate)
      for (int a = 0; a < 3; ++a)
        reach[a] = 1.01f * s.relocate_max_fraction * (desc.spacing[a] > 0.f ? desc.spacing[a] : cell);
    check_task.start(*arena, [&] { closed_check = ClosedMeshCheck(scene, rest_positions, reach); });
  }

  // --- set-up: BVH, mips, enclosure voxels and the Vulkan session side by side (those not given) ---
  BakeSetupParts parts;
  parts.bvh = s.prepared == nullptr;
  parts.mips = s.texture_lod == nullptr;
  parts.enclosure = s.voxels == nullptr;
  parts.gpu = s.gpu_session == nullptr;
  BakeSetup local_setup;
  BakeSetup& built = s.setup_out ? *s.setup_out : local_setup;  // what this bake builds
  if (parts.bvh || parts.mips || parts.enclosure || parts.gpu) {
    GIBAKE_TRY(build_bake_setup(scene, s, parts, ctx, *arena, built));
    for (const auto& st : built.stage_seconds) report.stage_seconds.push_back(st);
  }
  const PreparedScene* prepared = s.prepared ? s.prepared : built.prepared.get();
  const TextureLod& texture_lod = s.texture_lod ? *s.texture_lod : built.lod;
  const VoxelGrid* voxels = s.voxels ? s.voxels : (built.voxels.empty() ? nullptr : &built.voxels);
  report.masked_triangles = prepared->masked_triangles();

  GpuSession& gpu = s.gpu_session ? *s.gpu_session : built.gpu;
  TraceSetup setup;
  setup.prepared = prepared;
  setup.lod = &texture_lod;
  setup.cone_spread = std::sqrt(4.f * kernels::kPi / float(s.rays));
  setup.sky = &sky;
  setup.lights = lights.data();
  setup.light_count = static_cast<int>(lights.size());
  setup.random_light = s.light_sampling == LightSampling::Random;
  setup.seed = s.seed;
  const bool path_gather = s.gather == Gather::Path;
  EmitterTable emitters;
  if (path_gather) emitters = EmitterTable(scene);
  PathSetup path;
  path.trace = setup;
  path.emitters = &emitters;
  path.bounces = s.bounces;
  path.roulette_depth = s.roulette_depth;

  const std::vector<int32_t> all_probes = shard_probe_list(s.shard, probe_count);  // a shard's range, or all
  std::vector<float> offsets(size_t(probe_count) * 3, 0.f);
  auto probe_position = [&](int32_t p) {
    const auto rest = probe_rest_position(desc, p);
    return float3{rest[0] + offsets[p * 3], rest[1] + offsets[p * 3 + 1], rest[2] + offsets[p * 3 + 2]};
  };
  RayCapture* capture = s.capture_rays;
  if (capture) capture->assign(size_t(probe_count), {});
  // Unrotated spherical Fibonacci sets, once per ray count (each probe only rotates them).
  std::vector<float> fib_reloc(size_t(s.relocate_rays) * 3), fib_rays(size_t(s.rays) * 3);
  kernels::spherical_fibonacci_set(s.relocate_rays, fib_reloc.data());
  kernels::spherical_fibonacci_set(s.rays, fib_rays.data());

  // --- relocation ---
  auto t0 = Clock::now();
  std::vector<uint64_t> reloc_rays(probe_count, 0);
  std::vector<uint8_t> moved(probe_count, 0);
  const float min_cell = min_cell_size(desc);
  if (s.relocate && min_cell > 0.f && s.relocate_rays > 0) {
    RelocateParams rp;
    rp.threshold = s.relocate_fraction * min_cell;
    for (int a = 0; a < 3; ++a)
      rp.max_offset[a] = s.relocate_max_fraction * (desc.spacing[a] > 0.f ? desc.spacing[a] : min_cell);
    RelocationStage stage;
    stage.scene = &scene;
    stage.setup = setup;
    stage.gpu = gpu.active() ? gpu.tracer.get() : nullptr;
    stage.arena = arena.get();
    stage.seed = s.seed;
    stage.rays = s.relocate_rays;
    stage.iterations = s.relocate_iterations;
    stage.fibonacci = fib_reloc.data();
    stage.params = rp;
    stage.position = probe_position;
    stage.capture = capture;
    GIBAKE_TRY(relocate_probes(stage, all_probes, ctx, offsets, moved, reloc_rays));
  }
  report.stage_seconds.emplace_back("relocate", seconds_since(t0));

  // --- trace, fused with each probe's depth moments and pass-0 integration ---
  // A probe is finished as soon as its last batch is traced (right away without target_error):
  // stats, the ray-test state, depth moments, pass-0 SH and irradiance texels (emission + direct
  // + sky, every ray once), and the compact list of its bouncing hits -- all while its hit
  // records are still in cache. Only the bouncing hits are kept for the later passes.
  t0 = Clock::now();
  result.offsets.assign(size_t(probe_count) * 3, 0.f);
  ProbeIntegrateConfig ic;
  ic.probe_count = probe_count;
  ic.sh_order = s.sh_order;
  ic.max_distance = max_distance;
  ic.backface_threshold = s.backface_threshold;
  ic.keep_bounce_hits = !path_gather;  // the path gather's radiance already holds every bounce
  ic.voxels = voxels;
  ic.depth_layout = depth_layout;
  ic.position = probe_position;
  ic.relocation_rays = &reloc_rays;
  shard_integrator_config(s.shard, probe_count, ic);  // a shard holds its range only
  ProbeIntegrator integ(ic, result);
  std::vector<TraceCounters> counters(probe_count);
  // The path kernel on the Vulkan backend: whole paths (or, probe-feedback, first hits) on the device.
  std::unique_ptr<GpuPathTracer> gpu_path;
  std::unique_ptr<GpuIntegrator> gpu_integrate;  // SH, texels and depth moments on the device
  if (gpu.active()) {
    GpuPathSetup gs{&scene,    &texture_lod,     &emitters,         &lights,           &sky,        setup.random_light,
                    s.bounces, s.roulette_depth, setup.cone_spread, setup.shadow_bias, !path_gather};
    const auto tp = Clock::now();
    Status created;  // in the bake's arena: packing the texel pool runs in parallel, --threads bounds it
    arena->execute([&] { created = GpuPathTracer::create(*gpu.tracer, gs, gpu_path); });
    GIBAKE_TRY(created);
    GIBAKE_TRY(GpuIntegrator::create(*gpu.vk, s.sh_order, gpu_integrate));
    const double* st = gpu_path->setup_seconds();
    char line[256];
    std::snprintf(line, sizeof(line),
                  "vulkan: path gather setup %.3f s (shading data packed %.3f s, uploaded %.3f s, pipelines %.3f s)",
                  seconds_since(tp), st[0], st[1], st[2]);
    ctx.note(line);
  }
  TraceStage trace;
  trace.path = path;
  trace.path_gather = path_gather;
  trace.gpu = gpu_path.get();
  trace.integrate = gpu_integrate.get();
  trace.arena = arena.get();
  trace.seed = s.seed;
  trace.rays = s.rays;
  trace.max_rays = max_rays;
  trace.target_error = s.target_error;
  trace.fibonacci = fib_rays.data();
  trace.position = probe_position;
  trace.capture = capture;
  GIBAKE_TRY(trace_probes(trace, all_probes, ctx, integ, counters));
  report.stage_seconds.emplace_back("trace", seconds_since(t0));
  // The trace's device buffers (scene shading data, ray batches) are not needed by the bounce passes.
  gpu_path.reset();
  gpu_integrate.reset();

  // --- classification and bounces (side by side) ---
  result.offsets = offsets;
  std::vector<float> positions(size_t(probe_count) * 3);
  for (int32_t p = 0; p < probe_count; ++p) kernels::store3(&positions[p * 3], probe_position(p));
  if (s.shard) {  // the rest reads other probes: the merge's (bake/ddgi/shard_merge.h)
    result.settings_json = ddgi_settings_json(s, &gpu.choice);
    const ShardHandOff h{&positions, &offsets, &moved, &reloc_rays, &counters, &integ, &check_task, &closed_check};
    GIBAKE_TRY(hand_off_shard(s, h, *s.shard, result, report));
    report.seconds_total = seconds_since(t_start);
    return Status::ok();
  }
  BounceInputs bi = bounce_inputs(desc, s, offsets, integ, result);
  bi.positions = positions.data();
  for (int32_t p = 0; p < probe_count; ++p) report.bounce_hits += integ.bounce_hits[p].size();
  ClassifyReport cr;
  GIBAKE_TRY(classify_after_bounces(s, positions, bi, gpu.active() ? gpu.vk.get() : nullptr, *arena, ctx, check_task,
                                    closed_check, integ, result, cr, report));
  report.cgal_checked = cr.closed_mesh_checked;
  report.cgal_inside = cr.inside_by_cgal;
  report.cgal_disagreements = cr.disagreements;
  report.cgal_inactive_outside = cr.inactive_outside_closed;

  // --- outputs ---
  const bool any_light = integ.write_irradiance_atlas(irr_layout, result);

  report.probes = probe_count;
  for (int32_t p = 0; p < probe_count; ++p) {
    integ.refine_state(p, result.states[p]);
    report.enclosed += integ.enclosed[p];
    if (result.states[p] == ProbeState::Inactive)
      ++report.inactive;
    else if (result.states[p] == ProbeState::SkyOnly)
      ++report.sky_only;
    else
      ++report.active;
    report.bounce_rays += counters[p].bounce_rays;
    if (moved[p]) ++report.relocated;
    report.primary_rays += counters[p].rays;
    report.shadow_rays += counters[p].shadow_rays;
    report.relocation_rays += reloc_rays[p];
  }
  report.black = !any_light;
  if (report.black)
    ctx.warning(
        "the bake is black everywhere: no light, emission or sky reached any active probe "
        "(add --sun, --sky, lights or emissive materials)");
  result.settings_json = ddgi_settings_json(s, &gpu.choice);
  report.seconds_total = seconds_since(t_start);
  return Status::ok();
}

}  // namespace gibake
