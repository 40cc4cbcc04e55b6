#include "cli/bake_summary.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "bake/voxel/leak_warnings.h"

namespace gibake::cli {
namespace {

using ull = unsigned long long;

// What the default grid's fit to the voxels did (bake/ddgi/probe_grid.h).
nlohmann::json placement_json(const GridPlacement& p) {
  static const char* kSide[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  nlohmann::json dropped = nlohmann::json::object();
  for (int side = 0; side < 6; ++side)
    if (p.fit.dropped[side] > 0.f)
      dropped[kSide[side]] = {{"metres", p.fit.dropped[side]}, {"why", slab_reason_text(p.fit.why[side])}};
  nlohmann::json outer = nlohmann::json::array();
  for (int side = 0; side < 6; ++side)
    if (p.outer_layer[side]) outer.push_back(kSide[side]);
  return {{"fitted", p.fit.fitted},          {"box_min", p.fit.lo},
          {"box_max", p.fit.hi},             {"dropped", dropped},
          {"outer_layers", outer},
          {"unfitted_probes", p.unfitted_probes}, {"unfitted_spacing", p.unfitted_spacing}};
}

nlohmann::json ddgi_json(const DdgiReport& r) {
  nlohmann::json j{{"placement", placement_json(r.placement)},
                   {"probes",
                    {{"total", r.probes},
                     {"active", r.active},
                     {"inactive", r.inactive},
                     {"enclosed", r.enclosed},
                     {"sky_only", r.sky_only},
                     {"relocated", r.relocated}}},
                   {"rays",
                    {{"primary", r.primary_rays},
                     {"bounce", r.bounce_rays},
                     {"shadow", r.shadow_rays},
                     {"relocation", r.relocation_rays}}}};
  // A rate only where this run traced the rays (a merge counts the shards' rays, traced elsewhere).
  if (r.seconds_total > 0) j["mrays_per_s"] = double(r.total_rays()) / r.seconds_total / 1e6;
  return j;
}

nlohmann::json lpv_json(const LpvResult& l) {
  nlohmann::json cascades = nlohmann::json::array();
  for (const LpvCascade& c : l.cascades)
    cascades.push_back({{"dims", c.dims}, {"cell_size", c.cell_size}, {"iterations", c.iterations},
                        {"occlusion", c.occlusion}});
  return {{"cascades", cascades}, {"vpls", l.stats.vpls}, {"emissive_vpls", l.stats.emissive_vpls},
          {"interior_vpls", l.stats.interior_vpls}, {"vpl_rays", l.stats.vpl_rays}};
}

// Whether any active probe received light: a probe's relative error is that of its luminance, which
// a black probe does not have (it reads 0), so a bake without light measured no error at all.
bool any_probe_lit(const DdgiResult& result) {
  const size_t stride = size_t(result.desc.sh_coefficients()) * 3;
  // A shard's result keeps no SH (they went into the shard file): its errors were measured.
  if (result.sh.size() < result.states.size() * stride) return true;
  for (size_t p = 0; p < result.states.size() && (p + 1) * stride <= result.sh.size(); ++p) {
    if (result.states[p] == ProbeState::Inactive) continue;
    for (size_t k = 0; k < stride; ++k)
      if (result.sh[p * stride + k] != 0.f) return true;
  }
  return false;
}

constexpr const char* kAdaptiveUnmeasured = "no active probe received light, so no error was measured";

// Adaptive rays against their target (bake/ddgi/ddgi.h adaptive_outcome).
nlohmann::json adaptive_json(const DdgiResult& result, float target_error) {
  const AdaptiveOutcome o = adaptive_outcome(result, target_error);
  nlohmann::json j{{"target_error", target_error},
                   {"lit_probes", o.lit},
                   {"above_target", o.above_target},
                   {"median_error_above", o.median_error_above}};
  if (!any_probe_lit(result)) j["skipped"] = kAdaptiveUnmeasured;
  return j;
}

void print_adaptive_text(const DdgiResult& result, float target_error, size_t volumes) {
  if (!(target_error > 0.f)) return;
  const AdaptiveOutcome o = adaptive_outcome(result, target_error);
  if (o.lit == 0) return;
  const char* which = volumes > 1 ? " (volume 0)" : "";
  if (!any_probe_lit(result)) {
    std::fprintf(stderr, "  adaptive rays%s: skipped: %s\n", which, kAdaptiveUnmeasured);
    return;
  }
  if (o.above_target == 0) {
    std::fprintf(stderr, "  adaptive rays%s: every lit probe reached the target error %.3g\n", which,
                 double(target_error));
    return;
  }
  std::fprintf(stderr,
               "  adaptive rays%s: %u of %u lit probes (%.1f%%) stopped above the target error %.3g (median %.3g): "
               "the ray budget or --max-rays ran out first; where a view reads them, raise --ray-budget and "
               "--max-rays\n",
               which, o.above_target, o.lit, 100.0 * o.above_target / o.lit, double(target_error),
               double(o.median_error_above));
}

void print_ddgi_text(const DdgiResult& result, const DdgiReport& r, size_t volumes) {
  std::fprintf(stderr, "  probes: %d (%d active, %d inactive, %d relocated), grid %dx%dx%d\n", r.probes, r.active,
               r.inactive, r.relocated, result.desc.counts[0], result.desc.counts[1], result.desc.counts[2]);
  const std::string fit = placement_text(r.placement);
  if (!fit.empty()) std::fprintf(stderr, "  placement: %zu volume%s, spacing %.3g m; %s\n", volumes,
                                 volumes == 1 ? "" : "s (this: volume 0)", double(result.desc.spacing[0]), fit.c_str());
  if (r.enclosed || r.sky_only)
    std::fprintf(stderr, "  of which %d inactive in enclosed unlit space, %d see only sky (state sky-only)\n",
                 r.enclosed, r.sky_only);
  char rate[48] = "";  // only where this run traced the rays (not a merge's)
  if (r.seconds_total > 0)
    std::snprintf(rate, sizeof rate, ", %.2f Mrays/s", double(r.total_rays()) / r.seconds_total / 1e6);
  std::fprintf(stderr, "  rays: %llu (%llu primary, %llu bounce, %llu shadow, %llu relocation)%s\n",
               ull(r.total_rays()), ull(r.primary_rays), ull(r.bounce_rays), ull(r.shadow_rays), ull(r.relocation_rays),
               rate);
  if (r.filter.ran) std::fprintf(stderr, "  %s\n", probe_filter_summary(r.filter).c_str());
}

void print_lpv_text(const LpvResult& l) {
  if (l.cascades.empty()) return;
  const LpvCascade& c0 = l.cascades.front();
  std::fprintf(stderr, "  lpv: %zu cascade%s of %dx%dx%d cells (finest %.4g m), %d iterations, %s\n", l.cascades.size(),
               l.cascades.size() == 1 ? "" : "s", c0.dims[0], c0.dims[1], c0.dims[2], double(c0.cell_size),
               int(c0.iterations), c0.occlusion ? "voxel occlusion" : "no occlusion");
  const LpvStats& st = l.stats;
  std::string lights = st.vpl_rays == 0 ? std::string("no lights or sun to trace from")
                                        : std::to_string(st.vpls) + " where " + std::to_string(st.vpl_rays) +
                                              " rays from the lights met a surface";
  std::fprintf(stderr, "  lpv lights: %llu VPLs in all: %s, %llu on emissive surfaces; %llu dropped inside closed space\n",
               ull(st.vpls + st.emissive_vpls), lights.c_str(), ull(st.emissive_vpls), ull(st.interior_vpls));
}

std::string seconds_line(const std::vector<std::pair<std::string, double>>& timings) {
  std::string line = "  seconds:";
  const std::vector<std::pair<std::string, double>> stages = user_timings(timings);
  for (size_t i = 0; i < stages.size(); ++i) {
    line += " " + stages[i].first + " " + seconds_text(stages[i].second);
    if (stages[i].first == "set-up" && i + 1 < stages.size() && stages[i + 1].first.rfind(kSetupPart, 0) == 0) {
      line += " (";
      for (size_t k = i + 1; k < stages.size() && stages[k].first.rfind(kSetupPart, 0) == 0; ++k, ++i)
        line += stages[k].first.substr(std::string(kSetupPart).size()) + " " + seconds_text(stages[k].second) + ", ";
      line += "side by side)";
    }
    line += ",";
  }
  line.pop_back();
  return line;
}

void print_cgal_text(const DdgiReport& r) {
  if (!r.cgal_checked) return;
  std::fprintf(stderr,
               "  closed-mesh check (CGAL): %u probes inside closed solids, %u of them left active by the ray "
               "test; %u inactive probes outside every closed solid (open geometry)\n",
               r.cgal_inside, r.cgal_disagreements, r.cgal_inactive_outside);
}

// The backend the DDGI bake ran on and, for auto, the cost model's estimates and reason.
nlohmann::json backend_json(const BackendChoice& c) {
  nlohmann::json j{{"name", backend_name(c.backend)}, {"auto", c.automatic}};
  if (c.backend == Backend::Vulkan) j["device"] = c.device.name;
  if (c.automatic) {
    j["reason"] = c.decision.reason;
    if (c.decision.cpu_seconds > 0.0)
      j["estimate_s"] = {{"cpu", c.decision.cpu_seconds}, {"vulkan", c.decision.vulkan_seconds}};
  }
  return j;
}

}  // namespace

nlohmann::json reconstruction_json(const ReconstructionError& e) {
  return {{"source", e.source},
          {"patches", e.patches},
          {"counted", e.counted},
          {"within_10pct", e.shaded.within},
          {"ratio_p10", e.shaded.p10},
          {"ratio_median", e.shaded.median},
          {"ratio_p90", e.shaded.p90},
          {"p90_error", e.shaded.p90_error},
          {"indirect_within_10pct", e.indirect.within},
          {"indirect_ratio_median", e.indirect.median},
          {"indirect_p90_error", e.indirect.p90_error},
          {"reference_noise", e.reference_noise},
          {"retraced_patches", e.retraced},
          {"retraced_rays", e.retraced_rays},
          {"rays", e.rays},
          {"seconds", e.seconds}};
}

std::vector<std::pair<std::string, double>> user_timings(const std::vector<std::pair<std::string, double>>& timings) {
  static const std::pair<const char*, const char*> kWords[] = {
      {"prepare", "BVH"},
      {"voxelize (enclosure)", "enclosure voxels"},
      {"voxelize (grid fit)", "enclosure voxels (before the grid)"},
      {"texture mips", "texture mips"},
      {"vulkan (BVH, upload)", "GPU BVH and upload"},
      {"vulkan textures (packed, uploaded)", "GPU textures"},
      {"set-up (side by side)", "set-up"},
      {"relocate", "probe relocation"},
      {"trace", "ray tracing"},
      {"bounce1", "bounce 1"},
      {"bounces2+", "bounces 2+"},
      {"bounces (vulkan)", "bounces"},
      {"write_vdb", "write .vdb"},
      {"lpv_vpls", "LPV lights"},
      {"lpv_propagate", "LPV propagation"},
  };
  auto words = [](const std::string& name) {
    for (const auto& [key, text] : kWords)
      if (name == key) return std::string(text);
    return name;
  };
  auto is_setup_part = [](const std::string& name) {
    return name == "prepare" || name == "voxelize (enclosure)" || name == "texture mips" ||
           name == "vulkan (BVH, upload)" || name == "vulkan textures (packed, uploaded)";
  };
  // A later volume's stages come as "volume N <stage>" (cmd_bake.cpp): the same words after its name.
  auto split = [](const std::string& name) {
    if (name.rfind("volume ", 0) == 0) {
      const size_t space = name.find(' ', 7);
      if (space != std::string::npos && space > 7 &&
          name.find_first_not_of("0123456789", 7) == space)
        return std::make_pair(name.substr(0, space + 1), name.substr(space + 1));
    }
    return std::make_pair(std::string(), name);
  };
  std::vector<std::pair<std::string, double>> out, parts;
  double closed_mesh = 0.0;
  for (size_t i = 0; i < timings.size(); ++i) {
    const auto [prefix, name] = split(timings[i].first);
    const double sec = timings[i].second;
    if (prefix.empty() && is_setup_part(name)) {  // a part of the side-by-side set-up when the set-up follows them
      size_t j = i;
      while (j < timings.size() && is_setup_part(timings[j].first)) ++j;
      if (j < timings.size() && timings[j].first == "set-up (side by side)") {
        parts.emplace_back(kSetupPart + words(name), sec);
        continue;
      }
    }
    if (name == "closed-mesh check (task beside the stages)") continue;  // overlaps the other stages
    // Parts of other stages (the JSON summary lists them): the integrator's arrays, zeroed beside the
    // set-up and waited for inside the trace stage, and the write's parts.
    if (name.rfind("integrator arrays", 0) == 0 || name.rfind("write: ", 0) == 0) continue;
    if (name == "closed-mesh check wait" || name == "closed-mesh check (solids, queries)") {
      closed_mesh += sec;  // the time the check added to the bake
      if (i + 1 < timings.size()) {
        const auto next = split(timings[i + 1].first);
        if (next.first == prefix && next.second.rfind("closed-mesh check", 0) == 0) continue;
      }
      out.emplace_back(prefix + "closed-mesh check", closed_mesh);
      closed_mesh = 0.0;
      continue;
    }
    out.emplace_back(prefix + words(name), sec);
    if (name == "set-up (side by side)") {
      out.insert(out.end(), parts.begin(), parts.end());
      parts.clear();
    }
  }
  return out;
}

double peak_rss_mib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;  // ru_maxrss is KiB on Linux
}

std::string seconds_text(double s) { return std::to_string(s).substr(0, 6); }

void print_voxel_summary(const std::string& out, const VoxelReport& r, ProgressMode mode, const std::string& sizing) {
  if (mode == ProgressMode::Json) {
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& [stage, sec] : r.stage_seconds) stages[stage] = sec;
    nlohmann::json j{{"event", "voxels"},
                     {"out", out},
                     {"dims", r.dims},
                     {"voxel_size", r.voxel_size},
                     {"surface", r.surface_voxels},
                     {"interior", r.interior_voxels},
                     {"exterior", r.exterior_voxels},
                     {"fragments", r.fragments},
                     {"shadow_rays", r.shadow_rays},
                     {"estimated_mib", double(r.estimated_bytes) / 1048576.0},
                     {"timings_s", stages},
                     {"seconds", r.seconds_total}};
    std::fprintf(stderr, "%s\n", j.dump().c_str());
    return;
  }
  std::fprintf(stderr, "  voxels (%s): %dx%dx%d of %.4g m%s; %llu surface, %llu interior, %llu exterior; %llu fragments\n",
               out.c_str(), r.dims[0], r.dims[1], r.dims[2], double(r.voxel_size),
               sizing.empty() ? "" : (" (" + sizing + ", plus one empty voxel on every side and one spare)").c_str(), static_cast<unsigned long long>(r.surface_voxels),
               static_cast<unsigned long long>(r.interior_voxels), static_cast<unsigned long long>(r.exterior_voxels),
               static_cast<unsigned long long>(r.fragments));
  std::string stages = "  voxel seconds:";
  for (const auto& [stage, sec] : r.stage_seconds) stages += " " + stage + " " + seconds_text(sec) + ",";
  stages += " total " + seconds_text(r.seconds_total);
  std::fprintf(stderr, "%s\n", stages.c_str());
  std::fprintf(stderr, "  voxel memory: estimated %.1f MiB (peak of the process so far %.1f MiB)\n",
               double(r.estimated_bytes) / 1048576.0, peak_rss_mib());
  if (r.skipped_triangles > 0)
    std::fprintf(stderr, "  %llu triangles with non-finite vertices were skipped\n",
                 static_cast<unsigned long long>(r.skipped_triangles));
}

void print_bake_summary(const BakeSummary& s, ProgressMode mode) {
  if (mode == ProgressMode::Json) {
    nlohmann::json timings = nlohmann::json::object();
    for (const auto& [stage, sec] : s.timings) timings[stage] = sec;
    nlohmann::json j{{"event", "summary"}, {"out", s.out}, {"timings_s", timings}, {"peak_rss_mib", peak_rss_mib()}};
    if (s.report) j.update(ddgi_json(*s.report));
    if (s.result && s.target_error > 0.f) j["adaptive"] = adaptive_json(*s.result, s.target_error);
    if (s.backend) j["backend"] = backend_json(*s.backend);
    if (!s.volumes_json.empty()) j["volumes"] = nlohmann::json::parse(s.volumes_json);
    if (!s.volume_rule.empty()) j["detail_rule"] = s.volume_rule;
    if (!s.refine_rule.empty()) j["refinement"] = s.refine_rule;
    if (!s.quality.empty()) j["quality"] = s.quality;
    if (s.lpv) j["lpv"] = lpv_json(*s.lpv);
    if (s.reconstruction) j["reconstruction"] = reconstruction_json(*s.reconstruction);
    if (s.leaks) j["leak_audit"] = leak_json(*s.leaks, s.leak_exposure);
    std::fprintf(stderr, "%s\n", j.dump().c_str());
    if (s.voxels) print_voxel_summary(s.voxels_out, *s.voxels, mode);
    return;
  }
  std::fprintf(stderr, "gibake: wrote %s\n", s.out.c_str());
  if (s.voxels) print_voxel_summary(s.voxels_out, *s.voxels, mode, s.voxels_sizing);
  if (!s.quality.empty()) std::fprintf(stderr, "  %s\n", s.quality.c_str());
  if (s.result && s.report) print_ddgi_text(*s.result, *s.report, std::max<size_t>(1, s.volume_lines.size()));
  if (s.result) print_adaptive_text(*s.result, s.target_error, s.volume_lines.size());
  if (!s.volume_lines.empty()) {
    std::fprintf(stderr, "  %zu probe volumes (counts above: volume 0):\n", s.volume_lines.size());
    for (const std::string& line : s.volume_lines) std::fprintf(stderr, "    %s\n", line.c_str());
  }
  if (!s.volume_rule.empty()) std::fprintf(stderr, "  detail-volume rule: %s\n", s.volume_rule.c_str());
  if (!s.refine_rule.empty()) std::fprintf(stderr, "  %s\n", s.refine_rule.c_str());
  if (s.lpv) print_lpv_text(*s.lpv);
  if (s.leaks)
    std::fprintf(stderr,
                 "  leak audit: %llu thin-wall regions between lit and unlit space (walls under %.3g m), %zu of them "
                 "with active probes blending across (warned)\n",
                 ull(s.leaks->regions_total), double(s.leaks->probe_spacing),
                 s.leak_exposure ? ranked_exposed(*s.leak_exposure).size() : size_t(0));
  if (s.reconstruction) std::fprintf(stderr, "  %s\n", reconstruction_summary(*s.reconstruction).c_str());
  std::fprintf(stderr, "%s\n", seconds_line(s.timings).c_str());
  std::fprintf(stderr, "  peak memory: %.1f MiB\n", peak_rss_mib());
  if (s.report) print_cgal_text(*s.report);
}

}  // namespace gibake::cli
