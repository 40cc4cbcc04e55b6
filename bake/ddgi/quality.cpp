// The quality levels' presets (quality.h).
#include "bake/ddgi/quality.h"

#include <algorithm>
#include <cstdio>

namespace gibake {

const char* quality_name(Quality q) {
  switch (q) {
    case Quality::Draft: return "draft";
    case Quality::Final: return "final";
    case Quality::Default: break;
  }
  return "default";
}

std::vector<std::string> quality_names() { return {"draft", "default", "final"}; }

bool parse_quality(const std::string& text, Quality& out) {
  for (Quality q : {Quality::Draft, Quality::Default, Quality::Final})
    if (text == quality_name(q)) {
      out = q;
      return true;
    }
  return false;
}

// Draft doubles every bound of the spacing rule with an eighth of the probe budget. Final halves
// them with four times the budget, not eight: a probe takes about 1.3 KB of its file (f32 SH, an
// f16 irradiance atlas and an f16 depth atlas of 8x8 tiles), so a budget-bound grid's file stays
// within a few hundred MB; its cap of 32 batches and larger ray budget let the probes that stop
// above the target error at the default (lamp-lit and sunlit corners) reach it. Refinement
// (refine.h) spends a quarter of the probe budget at the default, half at final, none in a draft:
// the budget goes to the bricks of most contrast first, and around the rest the fit corrects the
// probes, where more refined probes add noise rather than light (docs/BENCHMARKS.md "The
// refinement's budget and the fit"). The refined probes add to the file beyond the grid's budget.
// Members: cells, min cells, min and max spacing (m), probe budget, rays, max rays, ray budget; the
// target error and bounces are the default's at every level.
QualityPreset quality_preset(Quality q) {
  QualityPreset p;  // default
  if (q == Quality::Default) return p;
  const bool draft = q == Quality::Draft;
  p.auto_cells = draft ? 12 : 48;
  p.auto_min_cells = draft ? 4 : 16;
  p.auto_min_spacing = draft ? 0.5f : 0.125f;
  p.auto_max_spacing = draft ? 2.f : 0.5f;
  p.probe_budget = draft ? 4096 : 131072;
  p.rays = draft ? 256 : 512;
  p.max_rays = draft ? 1024 : 16384;
  // final: six times the default's; its budget is shared by the probes not inside geometry, and
  // the refined volumes close to walls, where many are, need it (docs/BENCHMARKS.md "Probes inside").
  p.ray_budget = draft ? 512 : 6144;
  p.refine_budget = draft ? 0 : p.probe_budget / 2;
  p.refine_ray_budget = 0;  // the bake's rays: the default's own budget keeps it near a 2-core machine's time
  // Every level keeps the irradiance atlas: the samplers read a probe's irradiance from it (its
  // SH ring around bright sources below a surface's horizon), at about half of final's file.
  p.irradiance_atlas = true;
  p.depth_tile = draft ? p.depth_tile : 8;  // likewise: its depth tiles would be nine tenths of it
  p.probe_filter = draft;                   // the header says why a draft alone
  p.surface_fit = !draft;
  p.fit_samples = draft ? p.fit_samples : uint64_t(1) << 20;  // room for what its denser probes find
  p.fit_paths = draft ? p.fit_paths : 384;
  p.fit_roulette_depth = draft ? p.fit_roulette_depth : DdgiSettings{}.roulette_depth;  // as the probes' paths
  // Final's fit solves once, its residuals relative to the baked light: its points are many, so a
  // second solve costs time that final's bound cannot spare, for a small gain in the picture
  // (docs/BENCHMARKS.md "The fit's residual relative to its own light").
  p.fit_relative_to_fit = draft ? p.fit_relative_to_fit : 0.f;
  // Final's fit keeps the default's gather (both; quality.h says why) in one pass: on a device a
  // second pass traces its million points' paths again and solves them again, time that final's
  // bound cannot spare (docs/BENCHMARKS.md "The fit's second pass").
  p.fit_passes = draft ? p.fit_passes : 1;
  return p;
}

void apply_quality(Quality q, DdgiSettings& s) {
  const QualityPreset p = quality_preset(q);
  s.grid.auto_cells = p.auto_cells;
  s.grid.auto_min_cells = p.auto_min_cells;
  s.grid.auto_min_spacing = p.auto_min_spacing;
  s.grid.auto_max_spacing = p.auto_max_spacing;
  s.grid.auto_max_probes = p.probe_budget;
  s.rays = p.rays;
  s.max_rays = p.max_rays;
  s.ray_budget = p.ray_budget;
  s.target_error = p.target_error;
  s.bounces = p.bounces >= 0 ? p.bounces : s.gather == Gather::Path ? kPathGatherBounces : kProbeGatherBounces;
  s.irradiance_atlas = p.irradiance_atlas;
  s.depth_tile = p.depth_tile;
  s.filter.enabled = p.probe_filter;
  s.fit.enabled = p.surface_fit;
  s.fit.directions = p.fit_directions;
  s.fit.max_samples = p.fit_samples;
  s.fit.paths = p.fit_paths;
  s.fit.roulette_depth = p.fit_roulette_depth;
  s.fit.relative_to_fit = p.fit_relative_to_fit;
  s.fit.gather = p.fit_gather;
  s.fit.passes = p.fit_passes;
}

std::string quality_text(Quality q, const DdgiSettings& s, float spacing, const std::vector<std::string>& overridden,
                         uint64_t refine_budget, uint32_t refine_ray_budget) {
  char buf[512];
  const GridSettings& g = s.grid;
  std::string text = std::string("quality ") + quality_name(q) + ": spacing ";
  if (spacing > 0.f) {
    std::snprintf(buf, sizeof buf, "%.3g m ", double(spacing));
    text += buf;
  }
  std::snprintf(buf, sizeof buf,
                "(longest side / %d within %.3g-%.3g m, at least %d cells across, at most %llu probes), ", g.auto_cells,
                double(g.auto_min_spacing), double(g.auto_max_spacing), g.auto_min_cells,
                static_cast<unsigned long long>(g.auto_max_probes));
  text += buf;
  if (s.target_error > 0.f)
    std::snprintf(buf, sizeof buf, "rays %u-%u, ray budget %u, ", s.rays, probe_ray_cap(s), s.ray_budget);
  else
    std::snprintf(buf, sizeof buf, "rays %u, ", s.rays);
  text += buf;
  if (s.gather == Gather::Path && s.bounces == kPathGatherBounces) text += "bounces until roulette ends them";
  else text += "bounces " + std::to_string(s.bounces);
  if (refine_budget > 0) text += ", refined volumes within " + std::to_string(refine_budget) + " probes";
  // What the refined volumes are traced with (the same settings the plan gives them).
  const DdgiSettings refined = with_ray_budget(s, refine_ray_budget);
  if (refine_budget > 0 && refine_ray_budget > 0 && s.target_error > 0.f)
    text += " at a ray budget of " + std::to_string(refined.ray_budget);
  else if (refine_budget > 0 && refine_ray_budget > 0)
    text += " at " + std::to_string(refined.rays) + " rays a probe";
  if (!s.irradiance_atlas) text += ", no irradiance atlas";
  text += s.filter.enabled ? ", probe filter on" : ", probe filter off";
  if (s.fit.enabled && s.irradiance_atlas) {
    text += ", surface fit on (" + std::to_string(s.fit.max_samples) + " points found by " +
            std::to_string(s.fit.directions) + " rays a probe, " + std::to_string(s.fit.paths) +
            (s.fit.gather == FitGather::Probes
                 ? " one-bounce paths each, lit by the probes"
                 : " paths each, roulette from hit " + std::to_string(std::max(1, s.fit.roulette_depth)) +
                       (s.fit.gather != FitGather::Both ? ""
                        : s.fit.passes > 1              ? ", also ended in the probes fitted to the whole paths"
                                                        : ", also ended in the probes' light"));
    if (s.fit.relative_to_fit > 0.f) {
      std::snprintf(buf, sizeof buf, ", residuals relative to the fitted light to the power %.2g",
                    double(s.fit.relative_to_fit));
      text += buf;
    }
    text += ")";
  } else {
    text += ", surface fit off";
  }
  if (s.depth_tile != kDepthTexels)
    text += ", depth tiles " + std::to_string(s.depth_tile) + "x" + std::to_string(s.depth_tile);
  if (!overridden.empty()) {
    text += "; given explicitly: ";
    for (size_t i = 0; i < overridden.size(); ++i) text += (i ? ", " : "") + overridden[i];
  }
  return text;
}

}  // namespace gibake
