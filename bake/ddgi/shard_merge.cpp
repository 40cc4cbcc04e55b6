// Merging shard files (see shard_merge.h). The finishing steps mirror bake_ddgi's tail (bounce
// inputs, bounce passes, irradiance atlas, refined states, counts) on the assembled probes; the
// byte-identity tests (tests/bake/shard_merge_test.cpp) hold the two together.
#include "bake/ddgi/shard_merge.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <utility>

#include "bake/ddgi/bounce.h"
#include "bake/ddgi/classify.h"
#include "bake/ddgi/ddgi_device.h"
#include "bake/ddgi/ddgi_metadata.h"
#include "bake/ddgi/depth_tiles.h"
#include "bake/ddgi/probe_integrate.h"
#include "bake/run/arena.h"
#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_shard.h"
#include "io/bakefile/input_digest.h"
#include "io/timer.h"
#include "kernels/octahedral.h"

namespace gibake {
namespace {

bool same_grid(const DdgiShard& a, const DdgiShard& b) {
  return a.desc.grid_min == b.desc.grid_min && a.desc.grid_max == b.desc.grid_max && a.desc.counts == b.desc.counts &&
         a.desc.spacing == b.desc.spacing && a.desc.sh_order == b.desc.sh_order &&
         a.desc.max_distance == b.desc.max_distance && a.atlas_planes_per_row == b.atlas_planes_per_row &&
         a.irradiance_width == b.irradiance_width && a.irradiance_height == b.irradiance_height &&
         a.depth_width == b.depth_width && a.depth_height == b.depth_height && a.probe_gather == b.probe_gather &&
         a.sh_format == b.sh_format && a.atlas_format == b.atlas_format;
}

// What the finishing steps read of the settings JSON.
struct FinishSettings {
  bool probe_gather = false;
  int bounces = 0;
  float energy_conservation = 1.f, normal_bias = 0.f, smooth_backface = 0.f;
  std::string backend, vulkan_device, vulkan_driver;  // recorded when the bake ran on Vulkan
  ProbeFilterSettings filter;  // the one-go bake's, run here where every probe's neighbours are
  bool irradiance_atlas = true;  // DdgiSettings::irradiance_atlas (recorded only when false)
  int depth_tile = kDepthTexels;  // DdgiSettings::depth_tile (recorded only when coarsened)
};

Status parse_finish_settings(const std::string& json_text, FinishSettings& f) {
  try {
    const nlohmann::json j = nlohmann::json::parse(json_text);
    f.probe_gather = j.at("gather").get<std::string>() == "probes";
    f.bounces = j.at("bounces").get<int>();
    f.energy_conservation = j.at("energy_conservation").get<float>();
    f.normal_bias = j.at("normal_bias").get<float>();
    f.smooth_backface = j.at("smooth_backface").get<float>();
    f.backend = j.value("backend", "cpu");
    f.vulkan_device = j.value("vulkan_device", "");
    f.vulkan_driver = j.value("vulkan_driver", "");
    f.irradiance_atlas = j.value("irradiance_atlas", true);
    f.depth_tile = j.value("depth_tile", kDepthTexels);
    if (!valid_depth_tile(f.depth_tile)) return Status::invalid("", "settings", "depth_tile must be 16, 8 or 4");
    if (j.contains("probe_filter")) {
      f.filter.enabled = j.at("probe_filter").at("mode").get<std::string>() == "on";
      f.filter.noise_k = j.at("probe_filter").at("noise_k").get<float>();
    }
  } catch (const nlohmann::json::exception& e) {
    return Status::invalid("", "settings", std::string("cannot read the bake settings: ") + e.what());
  }
  return Status::ok();
}

// Copies shard probes into the integrator's per-probe arrays (and the result's offsets and stats),
// releasing each shard's arrays once copied.
void assemble(DdgiShard& sh, ProbeIntegrator& integ, DdgiResult& result, std::vector<uint8_t>& moved,
              std::vector<TraceCounters>& counters, std::vector<uint64_t>& reloc) {
  const size_t coefs = size_t(result.desc.sh_coefficients()) * 3;
  const size_t irr = size_t(ProbeIntegrator::kIrradianceTile);
  const size_t depth = size_t(kShardDepthTile) * kShardDepthTile * 2;
  const float* hit = sh.bounce_hits.data();
  for (size_t i = 0; i < sh.probes.size(); ++i) {
    const size_t p = sh.range.begin + i;
    const DdgiShardProbe& q = sh.probes[i];
    for (int a = 0; a < 3; ++a) result.offsets[p * 3 + a] = q.offset[a];
    result.stats[p] = q.stats;
    integ.inactive[p] = q.inactive;
    integ.enclosed[p] = q.enclosed;
    integ.sky_only[p] = q.sky_only;
    integ.probe_rays[p] = q.integrated_rays;
    moved[p] = q.moved;
    counters[p].rays = q.primary_rays;
    counters[p].shadow_rays = q.shadow_rays;
    counters[p].bounce_rays = q.bounce_rays;
    reloc[p] = q.relocation_rays;
    std::copy_n(&sh.sh0[i * coefs], coefs, &integ.sh0[p * coefs]);
    std::copy_n(&sh.irradiance[i * irr], irr, &integ.irradiance[p * irr]);
    std::copy_n(&sh.depth_tiles[i * depth], depth, &integ.depth_tiles[p * depth]);
    std::vector<BounceHit>& hits = integ.bounce_hits[p];
    hits.resize(q.bounce_hits);
    for (BounceHit& b : hits) {
      std::copy_n(hit, 4, b.dir_t);
      std::copy_n(hit + 4, 3, b.normal);
      std::copy_n(hit + 7, 3, b.albedo);
      hit += kShardHitFloats;
    }
  }
  // The identity (hashes, range, grid) stays for the checks; the probe data goes.
  std::vector<DdgiShardProbe>().swap(sh.probes);
  for (std::vector<float>* v : {&sh.sh0, &sh.irradiance, &sh.depth_tiles, &sh.bounce_hits})
    std::vector<float>().swap(*v);
}

// The depth atlas from the bordered tiles, as ProbeIntegrator::write_depth_tile places them.
void write_depth_atlas(const kernels::AtlasLayout& layout, const ProbeIntegrator& integ, DdgiResult& result) {
  const int tile = kShardDepthTile;
  for (int32_t p = 0; p < result.desc.probe_count(); ++p) {
    const float* t = &integ.depth_tiles[size_t(p) * tile * tile * 2];
    int ox, oy;
    layout.tile_origin(p, ox, oy);
    for (int y = 0; y < tile; ++y)
      std::copy(t + y * tile * 2, t + (y + 1) * tile * 2,
                &result.depth_atlas[(size_t(oy + y) * result.depth_width + ox) * 2]);
  }
}

// bake_ddgi's bounce inputs on the assembled probes.
BounceInputs finish_inputs(const FinishSettings& f, const std::vector<float>& positions, const ProbeIntegrator& integ,
                           const DdgiResult& result) {
  BounceParams params;
  params.normal_bias = f.normal_bias;
  params.smooth_backface = f.smooth_backface;
  params.bounces = f.probe_gather ? f.bounces : 0;
  params.energy_conservation = f.energy_conservation;
  return make_bounce_inputs(result, params, integ, positions);
}

// Whether the bounce passes run on a device: a probe-feedback bake made on Vulkan.
bool bounces_on_device(const FinishSettings& f) { return f.backend == "vulkan" && f.probe_gather && f.bounces > 0; }

// The device those bounce passes open: the one asked for, else the one the settings name.
BackendSettings bounce_backend(const FinishSettings& f, const MergeOptions& o) {
  BackendSettings bs = o.backend;
  if (bs.backend != Backend::Vulkan || bs.vulkan_device.empty()) {
    bs.backend = Backend::Vulkan;
    const bool lavapipe = f.vulkan_device.find("llvmpipe") != std::string::npos;
    bs.vulkan_device = lavapipe ? "lavapipe" : f.vulkan_device;
  }
  return bs;
}

// The bounce passes where the bake ran them: on the CPU, or (a probe-feedback bake made on Vulkan)
// on a device of the kind its settings name, so the merged bytes are the ones that bake wrote.
Status finish_bounces(const FinishSettings& f, const BounceInputs& bi, const MergeOptions& o, const Context& ctx,
                      tbb::task_arena& arena, ProbeIntegrator& integ, DdgiResult& result, DdgiReport& report) {
  BounceTimes times;
  if (!bounces_on_device(f)) {
    GIBAKE_TRY(
        make_cpu_ddgi_device(BackendChoice{}, arena)->bounce_passes(bi, ctx, result.sh, integ.irradiance, times));
    for (const auto& st : times.stage_seconds) report.stage_seconds.push_back(st);
    return Status::ok();
  }
  if (!o.platform)
    return Status::error(ExitCode::RuntimeFailure, "", "merge", "no platform to run the bounce passes on a device");
  std::shared_ptr<GpuSession> opened;
  BackendChoice choice;
  if (!o.session) GIBAKE_TRY(o.platform->open_session(bounce_backend(f, o), opened, choice));
  const std::unique_ptr<DdgiDevice> device = o.platform->device(o.session ? *o.session : *opened, arena);
  if (o.session) choice = device->choice();
  if (choice.device.name != f.vulkan_device || choice.device.driver != f.vulkan_driver)
    return Status::error(ExitCode::RuntimeFailure, "", "merge",
                         "the bounce passes must run on the device the shards ran on (" + f.vulkan_device + ", " +
                             f.vulkan_driver + "), found " + choice.device.name);
  GIBAKE_TRY(device->bounce_passes(bi, ctx, result.sh, integ.irradiance, times));
  for (const auto& st : times.stage_seconds) report.stage_seconds.push_back(st);
  return Status::ok();
}

// States and counts from the assembled probes, as bake_ddgi's refine_state and report loop.
void finish_report(const ProbeIntegrator& integ, const std::vector<uint8_t>& moved,
                   const std::vector<TraceCounters>& counters, const std::vector<uint64_t>& reloc, DdgiResult& result,
                   DdgiReport& report) {
  const int32_t n = result.desc.probe_count();
  result.states.assign(size_t(n), ProbeState::Active);
  report.probes = n;
  for (int32_t p = 0; p < n; ++p) {
    // The ray test's Inactive (back faces) or the enclosure's; else sky-only when no ray met geometry.
    ProbeState& st = result.states[p];
    st = integ.inactive[p] ? ProbeState::Inactive : integ.sky_only[p] ? ProbeState::SkyOnly : ProbeState::Active;
    report.enclosed += integ.enclosed[p];
    report.left_out += integ.inactive[p] && counters[p].rays == 0;  // a near volume's, never traced
    report.inactive += st == ProbeState::Inactive;
    report.sky_only += st == ProbeState::SkyOnly;
    report.active += st == ProbeState::Active;
    report.relocated += moved[p];
    report.primary_rays += counters[p].rays;
    report.shadow_rays += counters[p].shadow_rays;
    report.bounce_rays += counters[p].bounce_rays;
    report.relocation_rays += reloc[p];
    report.bounce_hits += integ.bounce_hits[p].size();
  }
  result.sparse = report.left_out > 0;  // as the one-go bake's (DdgiBake::classify)
}

}  // namespace

Status check_shard_part(const std::vector<std::string>& paths, const std::vector<DdgiShard>& first,
                        const std::vector<DdgiShard>& part, size_t i, std::vector<size_t>& order) {
  const DdgiShard& ref = first[0];
  const DdgiShard& s = part[0];
  const uint32_t count = ref.range.count;
  if (order.size() != count) order.assign(count, SIZE_MAX);
  if (s.input_hash != ref.input_hash || s.settings_hash != ref.settings_hash)
    return Status::invalid(paths[i], "shard_info",
                           "from another bake: input hash " + hash_text(s.input_hash) + ", settings hash " +
                               hash_text(s.settings_hash) + " (" + paths[0] + ": " + hash_text(ref.input_hash) + ", " +
                               hash_text(ref.settings_hash) + ")");
  if (s.range.count != count)
    return Status::invalid(
        paths[i], "shard_info",
        "one of " + std::to_string(s.range.count) + " shards, but " + paths[0] + " is one of " + std::to_string(count));
  if (part.size() != first.size())
    return Status::invalid(paths[i], "shard_info",
                           std::to_string(part.size()) + " probe volumes, but " + paths[0] + " has " +
                               std::to_string(first.size()));
  for (size_t v = 0; v < part.size(); ++v)
    if (!same_grid(part[v], first[v]))
      return Status::invalid(paths[i], "shard_info",
                             "a different grid or storage format than " + paths[0] + " (volume " + std::to_string(v) + ")");
  if (s.metadata_json != ref.metadata_json)  // the scene path as given, the tool version
    return Status::invalid(paths[i], "metadata", "differs from " + paths[0] + "'s (scene path or gibake version)");
  if (order[s.range.index] != SIZE_MAX)
    return Status::invalid(paths[i], "shard_info",
                           "shard " + std::to_string(s.range.index) + " of " + std::to_string(count) +
                               " given twice (also " + paths[order[s.range.index]] + ")");
  // A shard's light is merged as it is: a value that is no number would spread into the whole
  // file's (verify's "finite" check), so a part that holds one is refused here.
  for (size_t v = 0; v < part.size(); ++v) {
    const DdgiShard& p = part[v];
    for (const auto& [name, values] : {std::pair<const char*, const std::vector<float>*>{"sh", &p.sh0},
                                       {"irradiance", &p.irradiance},
                                       {"depth", &p.depth_tiles},
                                       {"bounce hits", &p.bounce_hits}}) {
      const size_t bad =
          size_t(std::count_if(values->begin(), values->end(), [](float x) { return !std::isfinite(x); }));
      if (bad > 0)
        return Status::invalid(paths[i], "volume " + std::to_string(v) + " " + name,
                               std::to_string(bad) + " NaN or infinite values (a damaged shard: bake it again)");
    }
  }
  order[s.range.index] = i;
  return Status::ok();
}

Status check_shards_complete(const DdgiShard& first, const std::vector<size_t>& order) {
  for (uint32_t k = 0; k < order.size(); ++k)
    if (order[k] == SIZE_MAX) {
      const uint64_t total = first.total_blocks, n = first.range.count;
      return Status::invalid("", "merge",
                             "shard " + std::to_string(k) + " of " + std::to_string(n) + " (probe blocks [" +
                                 std::to_string(total * k / n) + ", " + std::to_string(total * (k + 1) / n) +
                                 ") of " + std::to_string(total)  + ") is missing");
    }
  return Status::ok();
}

// The per-probe arrays bake_ddgi has after its trace, filled shard by shard.
struct ShardAssembly::State {
  State(const DdgiShard& first, DdgiResult& result) : integ(config(first), result) {
    const int32_t n = first.desc.probe_count();
    result.offsets.assign(size_t(n) * 3, 0.f);
    moved.assign(size_t(n), 0);
    counters.resize(size_t(n));
    reloc.assign(size_t(n), 0);
  }
  static ProbeIntegrateConfig config(const DdgiShard& first) {
    ProbeIntegrateConfig ic;
    ic.probe_count = first.desc.probe_count();
    ic.sh_order = first.desc.sh_order;
    ic.max_distance = first.desc.max_distance;
    ic.keep_bounce_hits = first.probe_gather;
    for (int a = 0; a < 3; ++a) ic.depth_layout.counts[a] = first.desc.counts[a];
    ic.depth_layout.res = kDepthTexels;
    ic.depth_layout.planes_per_row = first.atlas_planes_per_row;
    return ic;
  }
  ProbeIntegrator integ;
  std::vector<uint8_t> moved;
  std::vector<TraceCounters> counters;
  std::vector<uint64_t> reloc;
  ClassifyReport closed;  // summed over the shards
};

ShardAssembly::ShardAssembly(const DdgiShard& first, DdgiResult& result) : result_(result) {
  result_ = DdgiResult{};
  result_.desc = first.desc;
  result_.atlas_planes_per_row = first.atlas_planes_per_row;
  state_ = std::make_unique<State>(first, result_);
}

ShardAssembly::~ShardAssembly() = default;

void ShardAssembly::add(DdgiShard& shard) {
  ClassifyReport& c = state_->closed;
  c.closed_mesh_checked = c.closed_mesh_checked || shard.closed_checked;
  c.inside_by_cgal += shard.closed_inside;
  c.disagreements += shard.closed_inside_but_active;
  c.inactive_outside_closed += shard.closed_inactive_outside;
  assemble(shard, state_->integ, result_, state_->moved, state_->counters, state_->reloc);
}

Status open_bounce_session(const std::string& settings_json, const MergeOptions& options,
                           std::shared_ptr<GpuSession>& out) {
  FinishSettings f;
  GIBAKE_TRY(parse_finish_settings(settings_json, f));
  if (options.session || !options.platform || !bounces_on_device(f)) return Status::ok();
  BackendChoice choice;
  return options.platform->open_session(bounce_backend(f, options), out, choice);
}

Status ShardAssembly::finish(const std::string& settings_json, const MergeOptions& options, const Context& ctx,
                             DdgiReport& report, bool warn_black) {
  FinishSettings f;
  GIBAKE_TRY(parse_finish_settings(settings_json, f));
  report = DdgiReport{};
  ProbeIntegrator& integ = state_->integ;
  DdgiResult& result = result_;
  const int32_t n = result.desc.probe_count();
  kernels::AtlasLayout irr_layout, depth_layout;
  for (int a = 0; a < 3; ++a) irr_layout.counts[a] = depth_layout.counts[a] = result.desc.counts[a];
  irr_layout.res = kIrradianceTexels;
  depth_layout.res = kDepthTexels;
  irr_layout.planes_per_row = depth_layout.planes_per_row = result.atlas_planes_per_row;
  auto t0 = Clock::now();
  write_depth_atlas(depth_layout, integ, result);
  std::vector<float> positions(size_t(n) * 3);
  for (int32_t p = 0; p < n; ++p) {
    const auto rest = probe_rest_position(result.desc, p);
    for (int a = 0; a < 3; ++a) positions[size_t(p) * 3 + a] = rest[a] + result.offsets[size_t(p) * 3 + a];
  }
  const BounceInputs bi = finish_inputs(f, positions, integ, result);
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  GIBAKE_TRY(finish_bounces(f, bi, options, ctx, *arena, integ, result, report));
  bool any_light = false;
  arena->execute([&] {
    any_light = f.irradiance_atlas ? integ.write_irradiance_atlas(irr_layout, result) : integ.any_irradiance();
  });
  finish_report(integ, state_->moved, state_->counters, state_->reloc, result, report);
  report.cgal_checked = state_->closed.closed_mesh_checked;
  report.cgal_inside = state_->closed.inside_by_cgal;
  report.cgal_disagreements = state_->closed.disagreements;
  report.cgal_inactive_outside = state_->closed.inactive_outside_closed;
  report.black = !any_light;
  if (report.black && warn_black)
    ctx.warning(
        "the bake is black everywhere: no light, emission or sky reached any active probe "
        "(add --sun, --sky, lights or emissive materials)");
  result.settings_json = settings_json;
  report.stage_seconds.emplace_back("finish", seconds_since(t0));
  if (f.filter.enabled) {
    t0 = Clock::now();
    arena->execute([&] { filter_probes(result, f.filter, report.filter); });
    report.stage_seconds.emplace_back("probe filter", seconds_since(t0));
  }
  // After the filter, as the one-go bake (ddgi.cpp), so the bytes are the same.
  if (f.depth_tile != result.depth_tile) {
    t0 = Clock::now();
    arena->execute([&] { coarsen_depth_atlas(result, f.depth_tile); });
    report.stage_seconds.emplace_back("depth tiles coarsened", seconds_since(t0));
  }
  return Status::ok();
}

}  // namespace gibake
