#include "bake/ddgi/ddgi.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <vector>

#include "bake/ddgi/black_hint.h"
#include "bake/ddgi/bounce.h"
#include "bake/ddgi/classify.h"
#include "bake/ddgi/ddgi_bake.h"
#include "bake/ddgi/ddgi_device.h"
#include "bake/ddgi/ddgi_memory.h"
#include "bake/ddgi/depth_tiles.h"
#include "bake/ddgi/near_surface.h"
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
#include "bake/voxel/enclosure.h"
#include "bake/voxel/voxelize.h"
#include "io/size_text.h"
#include "io/timer.h"
#include "kernels/ddgi_sample.h"
#include "kernels/integrate.h"
#include "kernels/octahedral.h"
#include "kernels/ray_gen.h"
#include "kernels/sh.h"

namespace gibake {
using kernels::float3;

namespace {

// A probe ray's texture footprint as a share of its angular spacing sqrt(4 pi / rays): the lookup
// then filters about half of the surface the ray stands for (two texels of a level whose texel is a
// quarter of that spacing wide) instead of blurring into its neighbours' shares. Wider footprints
// read textured scenes measurably brighter than the truth; full resolution costs time and noise
// (docs/BENCHMARKS.md "The probe rays' texture footprints").
constexpr float kProbeConeShare = 0.25f;

Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "ddgi", what); }

Sky make_sky(const DdgiSettings& s, Status& status) {
  Sky sky;
  sky.constant = {s.sky[0], s.sky[1], s.sky[2]};
  status = Status::ok();
  if (!s.sky_hdr.empty()) {
    status = load_sky_exr(s.sky_hdr, sky);
    sky.scale = s.sky_hdr_scale;
  }
  return sky;
}

std::string grid_summary(const DdgiVolumeDesc& d, const GridSettings& g, const GridPlacement& placement) {
  char text[320];
  char automatic[160];
  std::snprintf(automatic, sizeof automatic,
                "default spacing rule: longest side / %d within %.3g..%.3g m, at least %d cells across, budget %llu "
                "probes",
                g.auto_cells, double(g.auto_min_spacing), double(g.auto_max_spacing), g.auto_min_cells,
                static_cast<unsigned long long>(g.auto_max_probes));
  const char* rule = g.counts[0] > 0 ? "--probe-counts" : g.spacing > 0.f ? "--probe-spacing" : automatic;
  if (d.probe_count() == 1) {  // no spacing to speak of: say where the one probe is
    std::snprintf(text, sizeof text, "probe grid 1x1x1 = 1 probe, at (%.3g, %.3g, %.3g) (%s)", d.grid_min[0],
                  d.grid_min[1], d.grid_min[2], rule);
    return text;
  }
  std::snprintf(text, sizeof text,
                "probe grid %dx%dx%d = %d probes, spacing %.3g x %.3g x %.3g m, from (%.3g, %.3g, %.3g) to (%.3g, "
                "%.3g, %.3g) (%s)",
                d.counts[0], d.counts[1], d.counts[2], d.probe_count(), d.spacing[0], d.spacing[1], d.spacing[2],
                d.grid_min[0], d.grid_min[1], d.grid_min[2], d.grid_max[0], d.grid_max[1], d.grid_max[2], rule);
  const std::string fit = placement_text(placement);
  return fit.empty() ? std::string(text) : std::string(text) + "; " + fit;
}

}  // namespace

// Grid, atlas layout, memory estimate, miss depth, sky and lights: everything before any work.
Status DdgiBake::plan() {
  GIBAKE_TRY(validate_ddgi_settings(s_));
  arena_ = make_arena(ctx_);
  GIBAKE_TRY(place_grid());
  desc_.sh_order = s_.sh_order;
  probe_count_ = desc_.probe_count();
  ctx_.note(grid_summary(desc_, s_.grid, report_.placement));
  max_rays_ = probe_ray_cap(s_);

  for (int a = 0; a < 3; ++a) irr_layout_.counts[a] = depth_layout_.counts[a] = desc_.counts[a];
  irr_layout_.res = kIrradianceTexels;
  depth_layout_.res = kDepthTexels;
  // One layout for both atlases, chosen so the wider (depth) one fits max_atlas_width.
  result_.atlas_planes_per_row =
      kernels::atlas_planes_per_row(desc_.counts[0], desc_.counts[1], depth_layout_.tile(), s_.max_atlas_width);
  irr_layout_.planes_per_row = depth_layout_.planes_per_row = result_.atlas_planes_per_row;

  // Miss depth: the user's, else the one the planner gave every volume, else this grid's own.
  if (s_.max_distance > 0.f)
    desc_.max_distance = s_.max_distance;
  else if (!(run_.placed && desc_.max_distance > 0.f))
    desc_.max_distance = miss_depth(scene_.bounds, {&desc_});

  Status sky_status;
  sky_ = make_sky(s_, sky_status);
  GIBAKE_TRY(sky_status);
  lights_ = shade_lights(scene_, s_.suns);
  // Before any work: refused on the figure of the backend chosen, or with auto of the lighter of
  // the two routes (either may be chosen: a small bake's is the CPU's, whose per-ray records weigh
  // less than the device's staging), judged again in set_up once auto has chosen; with vulkan
  // judged again there too, once the device says whether it is a GPU. A GpuSession handed in (the
  // volumes after the first) does not say the route: the CPU backend has one too. A near volume is
  // judged again once the near test has counted the probes it traces (leave_out_far_probes); until
  // then its figure leaves their records out.
  if (s_.backend.backend == Backend::Auto) return check_need(std::min(memory_need(true), memory_need(false)), false);
  const bool vulkan = s_.backend.backend == Backend::Vulkan;
  return check_need(memory_need(vulkan), !vulkan && !(s_.near_surface_reach > 0.f));
}

// The host working set estimated for the route (bake/ddgi/ddgi_memory.h).
uint64_t DdgiBake::memory_need(bool vulkan, bool vulkan_host_records) const {
  return estimate_ddgi_memory(memory_shape(vulkan, vulkan_host_records)).total();
}

DdgiMemoryShape DdgiBake::memory_shape(bool vulkan, bool vulkan_host_records) const {
  DdgiMemoryShape shape;
  shape.probes = uint64_t(probe_count_);
  // Before the near test (left_out_ not yet filled) a near volume counts none of its probes' records.
  const bool near_untested = s_.near_surface_reach > 0.f && left_out_.empty();
  shape.left_out = near_untested ? uint64_t(probe_count_) : uint64_t(report_.left_out);
  shape.sh_coefficients = desc_.sh_coefficients();
  shape.irradiance_texels = s_.irradiance_atlas ? uint64_t(irr_layout_.width()) * uint64_t(irr_layout_.height()) : 0;
  shape.depth_texels = uint64_t(depth_layout_.width()) * uint64_t(depth_layout_.height());
  shape.depth_tile = s_.depth_tile;
  shape.gather = s_.gather;
  shape.rays = s_.rays;
  shape.max_rays = max_rays_;
  shape.ray_budget = s_.ray_budget;
  shape.adaptive = s_.target_error > 0.f;
  const bool emissive = std::any_of(scene_.materials.begin(), scene_.materials.end(),
                                    [](const Material& m) { return m.is_emissive(); });
  shape.probe_lights = s_.gather == Gather::Path && (emissive || sky_.sampled());
  shape.vulkan = vulkan;
  shape.vulkan_host_records = vulkan_host_records;
  shape.probe_filter = s_.filter.enabled;
  shape.scene_bytes = scene_host_bytes(scene_, s_.enclosure_resolution);
  shape.held_bytes = run_.held_bytes;
  if (s_.fit.enabled && s_.irradiance_atlas)
    shape.fit_points = std::min<uint64_t>(s_.fit.max_samples, (shape.probes - shape.left_out) * s_.fit.directions);
  // The CPU reads the probes for the fit's ended paths through tables (CachedProbeField), except
  // where a device traces whole paths and ends them itself: a GPU, not a CPU device such as
  // lavapipe (make_gpu_reference_paths). Until the device is chosen, a GPU is assumed.
  const bool gpu = !device_ || device_->choice().device.is_gpu();
  const bool device_ends_paths = vulkan && gpu && s_.fit.gather == FitGather::Both;
  if (shape.fit_points && s_.fit.read_cell > 0.f && s_.fit.gather != FitGather::Paths && !device_ends_paths)
    shape.fit_read_tables = arena_ ? uint32_t(std::max(1, arena_->max_concurrency())) : 1u;
  shape.fit_second_pass = shape.fit_points && s_.fit.gather == FitGather::Both && s_.fit.passes > 1;
  if (shape.fit_second_pass && !device_ends_paths)
    shape.fit_kept_hits =
        fit_kept_hits((shape.probes - shape.left_out) * s_.fit.directions, s_.fit.max_samples, s_.fit.paths);
  return shape;
}

// The route's working set against --max-memory; `final`: the route is known, so the figure is noted.
Status DdgiBake::check_memory(bool vulkan, bool final) const { return check_need(memory_need(vulkan), final); }

Status DdgiBake::check_need(uint64_t need, bool final, const std::string& route) const {
  if (need > s_.max_memory_bytes)
    return bad("the bake would need about " + size_text(double(need)) + " of host memory" + route + ", over the " +
               size_text(double(s_.max_memory_bytes)) +
               " of --max-memory; raise --max-memory or use fewer probes or rays");
  if (final) {
    report_.memory_estimate = need;
    ctx_.note("memory: about " + std::to_string(need >> 20) + " MiB of host memory estimated" + route +
              " (--max-memory " + size_text(double(s_.max_memory_bytes)) + ")");
  }
  return Status::ok();
}

// The caller's placed grid (bake/ddgi/volume_plan.h), else the grid placed here.
Status DdgiBake::place_grid() {
  if (run_.placed) {
    desc_ = run_.placed->desc;
    report_.placement = run_.placed->placement;
    return Status::ok();
  }
  GIBAKE_TRY(placement_voxels());
  GIBAKE_TRY(place_probe_grid(scene_, s_.grid, desc_, placement_voxels_ref_, &report_.placement));
  if (!keep_placement_voxels_) placement_voxels_ = VoxelGrid{};  // built for the fit alone
  return Status::ok();
}

// The default grid is fitted to the enclosure voxels (bake/ddgi/probe_fit.h), so they are built
// before the grid rather than beside the BVH; the set-up then keeps them.
Status DdgiBake::placement_voxels() {
  const GridSettings& g = s_.grid;
  const bool automatic = !g.explicit_bounds && g.spacing == 0.f && g.counts[0] == 0 && g.fit_to_voxels;
  if (!automatic || scene_.bounds.empty()) return Status::ok();
  // Always at the enclosure test's resolution, also when the run context has a voxel grid (at
  // --voxel-res): the grid of a --ddgi bake does not depend on what else the run bakes.
  SetupSettings setup = setup_settings(s_);
  const bool keep = setup.enclosure_resolution > 0 && run_.voxels == nullptr;  // else for the fit alone
  if (setup.enclosure_resolution <= 0) setup.enclosure_resolution = 128;
  const auto t0 = Clock::now();
  GIBAKE_TRY(make_enclosure_voxels(scene_, setup, ctx_, placement_voxels_, arena_.get()));
  report_.stage_seconds.emplace_back("voxelize (grid fit)", seconds_since(t0));
  placement_voxels_ref_ = &placement_voxels_;
  keep_placement_voxels_ = keep;
  return Status::ok();
}

void DdgiBake::start_closed_mesh_check() {
  if (!s_.cgal_check || scene_.triangle_count() == 0) return;
  rest_positions_.resize(size_t(probe_count_) * 3);
  for (int32_t p = 0; p < probe_count_; ++p) {
    const auto rest = probe_rest_position(desc_, p);
    for (int a = 0; a < 3; ++a) rest_positions_[size_t(p) * 3 + a] = rest[a];
  }
  const float cell = min_cell_size(desc_);
  if (s_.relocate)
    for (int a = 0; a < 3; ++a)
      reach_[a] = 1.01f * s_.relocate_max_fraction * (desc_.spacing[a] > 0.f ? desc_.spacing[a] : cell);
  const SharedClosedMeshes* shared = run_.closed_meshes;
  check_task_.start(*arena_, [this, shared] {
    closed_check_ = shared ? ClosedMeshCheck(shared->tester(scene_), rest_positions_, reach_)
                           : ClosedMeshCheck(scene_, rest_positions_, reach_);
  });
}

// BVH, mips, enclosure voxels and the Vulkan session side by side (those the run context lacks),
// then what the tracers read.
Status DdgiBake::set_up() {
  BakeSetupParts parts;
  parts.bvh = run_.prepared == nullptr;
  parts.mips = run_.texture_lod == nullptr;
  parts.enclosure = run_.voxels == nullptr && !keep_placement_voxels_;
  parts.gpu = run_.gpu_session == nullptr;
  // A shard's bake runs no fit (its finish does).
  parts.probe_field_kernels = !run_.shard && s_.fit.enabled && s_.fit.gather == FitGather::Both;
  built_ = run_.setup_out ? run_.setup_out : &local_setup_;
  if (parts.bvh || parts.mips || parts.enclosure || parts.gpu) {
    SetupSettings setup = setup_settings(s_);
    setup.backend.workload =
        ddgi_workload(s_, uint64_t(probe_count_), scene_.triangle_count(), arena_->max_concurrency());
    GIBAKE_TRY(run_.platform->build_setup(scene_, setup, run_.vulkan_warmup, parts, ctx_, *arena_, *built_));
    for (const auto& st : built_->stage_seconds) report_.stage_seconds.push_back(st);
  }
  if (keep_placement_voxels_) built_->voxels = std::move(placement_voxels_);
  prepared_ = run_.prepared ? run_.prepared : built_->prepared.get();
  texture_lod_ = run_.texture_lod ? run_.texture_lod : &built_->lod;
  voxels_ = run_.voxels ? run_.voxels : (built_->voxels.empty() ? nullptr : &built_->voxels);
  device_ = run_.platform->device(run_.gpu_session ? *run_.gpu_session : *built_->gpu, *arena_);
  const bool near = s_.near_surface_reach > 0.f;
  if (s_.backend.backend != Backend::Cpu && !near)
    GIBAKE_TRY(check_memory(device_->choice().backend == Backend::Vulkan, true));
  report_.masked_triangles = prepared_->masked_triangles();

  trace_setup_.prepared = prepared_;
  trace_setup_.lod = texture_lod_;
  trace_setup_.cone_spread = kProbeConeShare * std::sqrt(4.f * kernels::kPi / float(s_.rays));
  trace_setup_.sky = &sky_;
  trace_setup_.lights = lights_.data();
  trace_setup_.light_count = static_cast<int>(lights_.size());
  trace_setup_.random_light = s_.light_sampling == LightSampling::Random;
  trace_setup_.seed = s_.seed;
  if (s_.gather == Gather::Path) emitters_ = EmitterTable(scene_);
  path_.trace = trace_setup_;
  path_.emitters = &emitters_;
  path_.bounces = s_.bounces;
  path_.roulette_depth = s_.roulette_depth;

  all_probes_ = shard_probe_list(run_.shard, probe_count_);  // a shard's range, or all
  leave_out_far_probes();
  if (near) GIBAKE_TRY(check_memory(device_->choice().backend == Backend::Vulkan, true));
  offsets_.assign(size_t(probe_count_) * 3, 0.f);
  if (run_.capture_rays) run_.capture_rays->assign(size_t(probe_count_), {});
  fib_reloc_.resize(size_t(s_.relocate_rays) * 3);
  fib_rays_.resize(size_t(s_.rays) * 3);
  kernels::spherical_fibonacci_set(s_.relocate_rays, fib_reloc_.data());
  kernels::spherical_fibonacci_set(s_.rays, fib_rays_.data());
  return Status::ok();
}

// With a near-surface reach: the probes far from every surface leave all_probes_ and are never
// traced; their neighbours' ray budget is shared by the probes that are (TraceStage::left_out).
void DdgiBake::leave_out_far_probes() {
  left_out_.assign(size_t(probe_count_), 0);
  if (!(s_.near_surface_reach > 0.f)) return;
  const auto t0 = Clock::now();
  left_out_ = probes_far_from_surfaces(*prepared_, desc_, all_probes_, s_.near_surface_reach, *arena_);
  all_probes_.erase(std::remove_if(all_probes_.begin(), all_probes_.end(), [&](int32_t p) { return left_out_[p]; }),
                    all_probes_.end());
  for (uint8_t far : left_out_) report_.left_out += far;
  report_.stage_seconds.emplace_back("probes near surfaces", seconds_since(t0));
}

// Everything the trace stage reads is known after the set-up: its device set-up (the path
// tracer's shading data, kernels and buffers on Vulkan) runs beside relocation.
void DdgiBake::begin_trace_setup(const TraceStage* stage) {
  const TraceStage* st = stage ? stage : &trace_stage_;
  trace_setup_task_.start(*arena_, [this, st] { trace_setup_status_ = begin_trace_stage(*st, *device_, ctx_); });
}

void DdgiBake::fill_trace_stage() {
  result_.offsets.assign(size_t(probe_count_) * 3, 0.f);
  TraceStage& trace = trace_stage_;
  trace.scene = &scene_;
  trace.path = path_;
  trace.lights = &lights_;
  trace.path_gather = s_.gather == Gather::Path;
  trace.sh_order = s_.sh_order;
  trace.arena = arena_.get();
  trace.seed = s_.seed;
  trace.rays = s_.rays;
  trace.max_rays = max_rays_;
  trace.target_error = s_.target_error;
  trace.ray_budget = s_.ray_budget;
  trace.backface_threshold = s_.backface_threshold;
  trace.counts = desc_.counts;
  trace.fibonacci = fib_rays_.data();
  trace.position = position_fn();
  trace.capture = run_.capture_rays;
  trace.left_out = report_.left_out > 0 ? &left_out_ : nullptr;
}

void DdgiBake::start_integrator() {
  ProbeIntegrateConfig ic;
  ic.probe_count = probe_count_;
  ic.sh_order = s_.sh_order;
  ic.max_distance = desc_.max_distance;
  ic.backface_threshold = s_.backface_threshold;
  ic.keep_bounce_hits = s_.gather != Gather::Path;  // the path gather's radiance already holds every bounce
  ic.depth_layout = depth_layout_;                  // the voxels come from the set-up: given once it is waited for
  ic.zero_irradiance_atlas = run_.shard == nullptr && s_.irradiance_atlas;  // a shard's atlas is the merge's
  ic.irradiance_layout = irr_layout_;
  ic.position = position_fn();
  ic.relocation_rays = &reloc_rays_;                        // filled by relocate(), read as probes finish
  shard_integrator_config(run_.shard, probe_count_, ic);    // a shard holds its range only
  ic.depth_tiles = ic.keep_bounce_hits || !ic.depth_atlas;  // read by the bounce passes or the merge
  integ_task_.start(*arena_, [this, ic] { integ_ = std::make_unique<ProbeIntegrator>(ic, result_); });
}

Status DdgiBake::relocate() {
  const auto t0 = Clock::now();
  reloc_rays_.assign(probe_count_, 0);
  moved_.assign(probe_count_, 0);
  const float min_cell = min_cell_size(desc_);
  if (s_.relocate && min_cell > 0.f && s_.relocate_rays > 0) {
    RelocationStage stage;
    stage.params.threshold = s_.relocate_fraction * min_cell;
    for (int a = 0; a < 3; ++a)
      stage.params.max_offset[a] = s_.relocate_max_fraction * (desc_.spacing[a] > 0.f ? desc_.spacing[a] : min_cell);
    stage.iterations = s_.relocate_iterations;
    RelocationRays& rays = stage.rays;
    rays.scene = &scene_;
    rays.setup = trace_setup_;
    rays.seed = s_.seed;
    rays.rays = s_.relocate_rays;
    rays.fibonacci = fib_reloc_.data();
    rays.position = position_fn();
    rays.capture = run_.capture_rays;
    GIBAKE_TRY(relocate_probes(stage, *device_, all_probes_, ctx_, offsets_, moved_, reloc_rays_));
  }
  report_.stage_seconds.emplace_back("relocate", seconds_since(t0));
  return Status::ok();
}

// Every probe's rays, fused with its depth moments and pass-0 integration: a probe is finished as
// soon as its last batch is traced (right away without target_error): stats, the ray-test state,
// depth moments, pass-0 SH and irradiance texels (emission + direct + sky, every ray once), and the
// compact list of its bouncing hits, while its hit records are still in cache. Only the bouncing
// hits are kept for the later passes.
Status DdgiBake::trace() {
  const auto t0 = Clock::now();
  std::vector<TraceCounters> counters(static_cast<size_t>(probe_count_));
  const auto begun = [this] { return trace_begun(); };
  const auto integrators = [this] { return std::vector<ProbeIntegrator*>{&trace_integrator()}; };
  GIBAKE_TRY(trace_probes(trace_stage_, *device_, all_probes_, ctx_, begun, integrators, counters));
  traced(std::move(counters), seconds_since(t0));
  return Status::ok();
}

// The device's set-up for the trace, run beside relocation (start_trace_setup).
Status DdgiBake::trace_setup_done() {
  trace_setup_task_.wait();
  return trace_setup_status_;
}

Status DdgiBake::trace_begun() {
  GIBAKE_TRY(trace_setup_done());
  // The estimate took the device to keep adaptive statistics itself; where it cannot (no 64-bit
  // floats), judged again on the host's records before the first ray.
  if (device_->choice().backend != Backend::Vulkan ||
      !device_->keeps_records_on_host(trace_stage_, size_t(probe_count_)))
    return Status::ok();
  return check_need(memory_need(true, true), true, " (the device keeps the rays' records on the host)");
}

// Waited for once the device is set up for the trace.
ProbeIntegrator& DdgiBake::trace_integrator() {
  const double waited = integ_task_.wait();
  report_.stage_seconds.emplace_back("integrator arrays (task beside)", integ_task_.seconds());
  report_.stage_seconds.emplace_back("integrator arrays wait", waited);
  integ_->set_enclosure_voxels(voxels_);
  for (int32_t p = 0; p < probe_count_; ++p)
    if (left_out_[size_t(p)]) integ_->leave_out(p);  // only a shard's own probes are marked
  // The filter changes the irradiance atlas after the trace: its rows are final only then; a row
  // streams once all its probes finish, which a left-out probe never does.
  if (!run_.shard && !s_.filter.enabled && s_.depth_tile == kDepthTexels && report_.left_out == 0)
    integ_->set_stream(run_.file_stream);
  return *integ_;
}

void DdgiBake::traced(std::vector<TraceCounters> counters, double seconds, const std::string& stage) {
  counters_ = std::move(counters);
  if (seconds > 0.0) report_.stage_seconds.emplace_back(stage, seconds);
}

Status DdgiBake::hand_off(bool& handed_off, double seconds_total) {
  handed_off = run_.shard != nullptr;
  if (!handed_off) return Status::ok();
  // The rest reads other probes: the merge's (bake/ddgi/shard_merge.h).
  result_.offsets = offsets_;
  const std::vector<float> positions = final_positions();
  result_.settings_json = ddgi_settings_json(s_, &device_->choice());
  const ShardHandOff h{&positions, &offsets_,    &moved_,      &reloc_rays_,
                       &counters_, integ_.get(), &check_task_, &closed_check_};
  GIBAKE_TRY(hand_off_shard(s_, h, *run_.shard, result_, report_));
  report_.seconds_total = seconds_total;
  return Status::ok();
}

// The states come from the ray test alone (the integrator's inactive[] uses the same rule), so the
// closed-mesh check only feeds the report; it is waited for after the bounce passes (on the bake's
// device). The bounce hits are released afterwards.
Status DdgiBake::classify() {
  ProbeIntegrator& integ = *integ_;
  result_.offsets = offsets_;
  const std::vector<float> positions = final_positions();
  BounceParams params;
  params.normal_bias = s_.normal_bias;
  params.smooth_backface = s_.smooth_backface;
  params.bounces = s_.gather == Gather::Path ? 0 : s_.bounces;
  params.energy_conservation = s_.energy_conservation;
  const BounceInputs bi = make_bounce_inputs(result_, params, integ, positions);
  for (int32_t p = 0; p < probe_count_; ++p) report_.bounce_hits += integ.bounce_hits[p].size();

  ray_test_states(result_.stats, s_.backface_threshold, result_.states);
  BounceTimes bounce_times;
  const Status bounced = device_->bounce_passes(bi, ctx_, result_.sh, integ.irradiance, bounce_times);
  for (const auto& st : bounce_times.stage_seconds) report_.stage_seconds.push_back(st);
  std::vector<std::vector<BounceHit>>().swap(integ.bounce_hits);
  GIBAKE_TRY(bounced);
  ClassifyReport cr;
  if (check_task_.started()) {
    const double waited = check_task_.wait();
    report_.stage_seconds.emplace_back("closed-mesh check (task beside the stages)", check_task_.seconds());
    report_.stage_seconds.emplace_back("closed-mesh check wait", waited);
    const auto t0 = Clock::now();
    arena_->execute([&] { cr = closed_check_.report(positions, result_.stats, result_.states); });
    report_.stage_seconds.emplace_back("closed-mesh check (solids, queries)", seconds_since(t0));
  }
  report_.cgal_checked = cr.closed_mesh_checked;
  report_.cgal_inside = cr.inside_by_cgal;
  report_.cgal_disagreements = cr.disagreements;
  report_.cgal_inactive_outside = cr.inactive_outside_closed;
  // After the check, which asks only about the probes whose rays it has seen.
  for (int32_t p = 0; p < probe_count_; ++p)
    if (left_out_[size_t(p)]) result_.states[size_t(p)] = ProbeState::Inactive;
  result_.sparse = report_.left_out > 0;  // the file keeps the probes near surfaces alone
  return Status::ok();
}

// The irradiance atlas, the final states and the report's counts.
void DdgiBake::finish(double seconds_total) {
  ProbeIntegrator& integ = *integ_;
  bool any_light = false;
  arena_->execute([&] {
    any_light = s_.irradiance_atlas ? integ.write_irradiance_atlas(irr_layout_, result_) : integ.any_irradiance();
  });
  report_.probes = probe_count_;
  for (int32_t p = 0; p < probe_count_; ++p) {
    integ.refine_state(p, result_.states[p]);
    report_.enclosed += integ.enclosed[p];
    if (result_.states[p] == ProbeState::Inactive)
      ++report_.inactive;
    else if (result_.states[p] == ProbeState::SkyOnly)
      ++report_.sky_only;
    else
      ++report_.active;
    report_.bounce_rays += counters_[p].bounce_rays;
    if (moved_[p]) ++report_.relocated;
    report_.primary_rays += counters_[p].rays;
    report_.shadow_rays += counters_[p].shadow_rays;
    report_.relocation_rays += reloc_rays_[p];
  }
  report_.black = !any_light;
  if (report_.left_out == probe_count_ && probe_count_ > 0 && !run_.shard) {
    char line[200];
    std::snprintf(line, sizeof line,
                  "a near volume (--probe-volume ...:near) has no surface within %.3g m of any of its %d probes: "
                  "none traced, it lights nothing",
                  double(s_.near_surface_reach), probe_count_);
    ctx_.warning(line);
  } else if (report_.black && run_.warn_black) {
    ctx_.warning(black_bake_warning(scene_light_sources(scene_, s_.suns, s_.sky, s_.sky_hdr),
                                    {report_.probes, report_.inactive, report_.cgal_inside, report_.cgal_checked}));
  }
  result_.settings_json = ddgi_settings_json(s_, &device_->choice());
  report_.seconds_total = seconds_total;
}

// On the host after every backend, as the shard merge does (probe_filter.h).
void DdgiBake::filter() {
  if (!s_.filter.enabled) return;
  const auto t0 = Clock::now();
  arena_->execute([&] { filter_probes(result_, s_.filter, report_.filter); });
  report_.stage_seconds.emplace_back("probe filter", seconds_since(t0));
}

// After the filter, which weighs neighbours with the full tiles' visibility, as the merge does.
void DdgiBake::coarsen_depth() {
  if (s_.depth_tile == result_.depth_tile) return;
  const auto t0 = Clock::now();
  arena_->execute([&] { coarsen_depth_atlas(result_, s_.depth_tile); });
  report_.stage_seconds.emplace_back("depth tiles coarsened", seconds_since(t0));
}

// On a device session, what the finished bake still holds (the integrator's host arrays, hundreds of
// MB on large grids; the device's relocation buffers; the closed-mesh check's solids) goes to the
// session's release thread, freed beside the leak audit and the write rather than on the way out.
// Every task that reads them is done.
void DdgiBake::release_beside() {
  GpuSession* session = run_.gpu_session ? run_.gpu_session : (built_ ? built_->gpu.get() : nullptr);
  ReleaseBeside* released = session && run_.platform ? run_.platform->release_thread(*session) : nullptr;
  if (!released) return;
  check_task_.wait();
  integ_task_.wait();
  trace_setup_task_.wait();
  released->release(std::move(integ_), std::move(device_),
                            std::make_unique<ClosedMeshCheck>(std::move(closed_check_)));
}

Status start_ddgi_bake(DdgiBake& bake, const RunContext& run) {
  if (!run.platform)  // a caller's mistake: the assembly hands one in (bake/pipeline/devices.h)
    return Status::error(ExitCode::RuntimeFailure, "", "ddgi", "no platform to bake on (RunContext::platform)");
  GIBAKE_TRY(bake.plan());
  bake.start_closed_mesh_check();
  bake.start_integrator();
  return bake.set_up();
}

Status end_ddgi_bake(DdgiBake& bake, DdgiReport& report, Clock::time_point start) {
  bool handed_off = false;
  GIBAKE_TRY(bake.hand_off(handed_off, seconds_since(start)));
  if (handed_off) return Status::ok();
  GIBAKE_TRY(bake.classify());
  bake.finish(seconds_since(start));
  bake.filter();
  bake.coarsen_depth();
  report.seconds_total = seconds_since(start);
  bake.release_beside();
  return Status::ok();
}

Status bake_ddgi(const Scene& scene, const DdgiSettings& s, const RunContext& run, const Context& ctx,
                 DdgiResult& result, DdgiReport& report) {
  const auto t_start = Clock::now();
  report = DdgiReport{};
  result = DdgiResult{};
  DdgiBake bake(scene, s, run, ctx, result, report);
  GIBAKE_TRY(start_ddgi_bake(bake, run));
  bake.start_trace_setup();
  GIBAKE_TRY(bake.relocate());
  GIBAKE_TRY(bake.trace());
  return end_ddgi_bake(bake, report, t_start);
}

AdaptiveOutcome adaptive_outcome(const DdgiResult& result, float target_error) {
  AdaptiveOutcome o;
  if (!(target_error > 0.f)) return o;
  std::vector<float> above;
  for (size_t p = 0; p < result.stats.size() && p < result.states.size(); ++p) {
    if (result.states[p] == ProbeState::Inactive) continue;
    ++o.lit;
    // The trace's rule (trace_batches.cpp): a probe gets more rays while its error is >= the target.
    if (result.stats[p].relative_error >= target_error) above.push_back(result.stats[p].relative_error);
  }
  o.above_target = uint32_t(above.size());
  if (!above.empty()) {
    std::nth_element(above.begin(), above.begin() + above.size() / 2, above.end());
    o.median_error_above = above[above.size() / 2];
  }
  return o;
}

}  // namespace gibake
