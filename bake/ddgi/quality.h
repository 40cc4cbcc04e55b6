// Quality levels (--quality draft|default|final): one word that sets the probe spacing rule, the
// probe budget, the rays and the bounces coherently. A level is a preset of DdgiSettings, applied
// first; options given explicitly are applied over it and win.
//
// * default: the CLI's defaults, so `--quality default` bakes the same bytes as no --quality at
//   all, with refined volumes (refine.h) within a quarter of the probe budget. Sized for a 2-core
//   machine.
// * draft: twice the default rule's spacing (an eighth of the probes, budget included), half the
//   rays a batch, a quarter of the ray budget, a cap of 4 batches and no refinement: a quick look
//   on the CPU.
// * final: half the default rule's spacing (eight times the probes, within four times the probe
//   budget), a cap of 32 batches and six times the ray budget, and refined volumes at half that
//   spacing where the direct light changes (refine.h), within half the probe budget: what a GPU
//   makes affordable. Its files store depth tiles of 8x8 texels (depth_tiles.h): with its many
//   probes the full tiles would be most of the file. Every level keeps the irradiance atlas the
//   samplers read.
// * The probe filter (probe_filter.h) runs in a draft alone, whose probes take few rays and whose
//   atlases are not fitted: it trades some sharpness where light changes for far less noise. Where
//   the surface fit runs (default, final), the fit corrects the probes where surfaces read them and
//   the filter's smoothing only costs sharpness (docs/BENCHMARKS.md "The probe filter and the fit").
// * The surface fit (surface_fit.h) runs at default and final: the atlases fitted to path-traced
//   surface points close most of what interpolation between probes misses where light changes
//   within a spacing. Points count for more than paths: the default spends its fit on 64 rays a
//   probe to find points and 144 paths each rather than half the points at twice the paths, its
//   paths ended by roulette from their first hit so that more of them fit the time, and takes the
//   time from the grid's ray budget, which the fit makes up for (docs/BENCHMARKS.md "The fit's
//   points", "The default's arcade: one bake's noise"). final traces up to four times the points
//   with 384 paths each, roulette after three hits as the reference's (a GPU's work: far fewer
//   paths leave the fit following the paths' noise in shade); a draft skips it. Both
//   levels' paths also read the probes at their first hit (--fit-gather both, fit_gather.h): whole
//   paths alone are too noisy where light arrives through many bounces (closed rooms at 128 paths
//   a point) or through gaps (a sunlit arcade even at 512), and a GPU ends them in the same
//   pass. Beside lamps final's fine probes mislead the ended paths a little: closed rooms lit by a
//   lamp read better with --fit-gather paths at final (docs/TUNING.md).
// The path gather's bounces stay roulette-ended in every level (a probe holds converged light,
// DESIGN.md; truncating them biases the light, it does not only add noise), the probe-feedback
// gather keeps its passes; the target error stays too: the ray budget is what buys accuracy.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/refine.h"

namespace gibake {

enum class Quality : uint8_t { Draft = 0, Default = 1, Final = 2 };

const char* quality_name(Quality quality);
// "draft", "default" or "final"; false for anything else.
bool parse_quality(const std::string& text, Quality& out);
// The level names, in the order they are listed.
std::vector<std::string> quality_names();

// What a level sets. bounces -1: the gather's default (kPathGatherBounces, kProbeGatherBounces).
// The default level's refinement and fit are the library's own defaults (RefineSettings,
// SurfaceFitSettings), so that a library bake and the CLI's default agree and a default bake's
// volumes record no customised refinement (VolumeSettings::refined_otherwise).
struct QualityPreset {
  int32_t auto_cells = 24, auto_min_cells = 8;
  float auto_min_spacing = 0.25f, auto_max_spacing = 1.f;
  uint64_t probe_budget = 32768;  // GridSettings::auto_max_probes (--probe-budget)
  uint32_t rays = 512, max_rays = 0, ray_budget = 1024;
  float target_error = 0.05f;
  int bounces = -1;
  uint64_t refine_budget = RefineSettings{}.budget;  // VolumeSettings::refine.budget (--refine-budget)
  // RefineSettings::ray_budget (--refine-ray-budget); 0: the bake's
  uint32_t refine_ray_budget = RefineSettings{}.ray_budget;
  bool irradiance_atlas = true;       // DdgiSettings::irradiance_atlas (--irradiance-atlas)
  int depth_tile = kDepthTexels;      // DdgiSettings::depth_tile (--depth-tile)
  bool probe_filter = false;          // DdgiSettings::filter.enabled (--probe-filter)
  bool surface_fit = true;            // DdgiSettings::fit.enabled (--surface-fit)
  uint32_t fit_directions = SurfaceFitSettings{}.directions;  // DdgiSettings::fit.directions (--fit-directions)
  uint64_t fit_samples = SurfaceFitSettings{}.max_samples;   // DdgiSettings::fit.max_samples (--fit-samples)
  uint32_t fit_paths = SurfaceFitSettings{}.paths;           // DdgiSettings::fit.paths (--fit-paths)
  int fit_roulette_depth = SurfaceFitSettings{}.roulette_depth;  // DdgiSettings::fit.roulette_depth
  float fit_relative_to_fit = SurfaceFitSettings{}.relative_to_fit;  // DdgiSettings::fit.relative_to_fit
  FitGather fit_gather = SurfaceFitSettings{}.gather;         // DdgiSettings::fit.gather (--fit-gather)
  uint32_t fit_passes = SurfaceFitSettings{}.passes;          // DdgiSettings::fit.passes (--fit-passes)
};
QualityPreset quality_preset(Quality quality);

// Fills the members a level governs: the grid's spacing rule and probe budget, rays, max_rays,
// ray_budget, target_error, bounces (for settings.gather, so set the gather first) and whether the
// file keeps an irradiance atlas.
void apply_quality(Quality quality, DdgiSettings& settings);

// One line for the bake's summary: the level and what it chose, e.g. "quality final: spacing
// 0.5 m (longest side / 48 within 0.125-0.5 m, at most 131072 probes), rays 512-16384, ray budget
// 4096, bounces until roulette ends them, depth tiles 8x8; given explicitly: --rays". `settings` are the bake's
// (after the explicit options), `spacing` the default grid's spacing as placed (0: not known),
// `overridden` the options given explicitly among those the level sets, `refine_budget` the
// refinement's probe budget (0: none) and `refine_ray_budget` RefineSettings::ray_budget (0: the
// bake's rays; otherwise the line says what the refined volumes are traced with).
std::string quality_text(Quality quality, const DdgiSettings& settings, float spacing,
                         const std::vector<std::string>& overridden, uint64_t refine_budget = 0,
                         uint32_t refine_ray_budget = 0);

}  // namespace gibake
