// DdgiSettings as a JSON object, their validation, and what the set-up reads of them.
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/depth_tiles.h"
#include "bake/run/bake_setup.h"

namespace gibake {
namespace {

Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "ddgi", what); }

}  // namespace

// Members whose JSON key is their own name, each named once; the rest are written by hand below.
// (The macro also defines a from_json, which nothing calls: settings are never read back.)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(GridSettings, padding, spacing, counts, explicit_bounds, grid_min, grid_max,
                                   auto_cells, auto_min_spacing, auto_min_cells, auto_max_spacing, auto_max_probes,
                                   max_probes)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(DdgiSettings, grid, rays, max_rays, target_error, ray_budget, seed, bounces, roulette_depth,
                                   energy_conservation, sh_order, sky, sky_hdr, sky_hdr_scale, relocate,
                                   relocate_fraction, relocate_max_fraction, relocate_rays, relocate_iterations,
                                   backface_threshold, blend_cutoff, enclosure_resolution, max_atlas_width,
                                   normal_bias, smooth_backface, max_distance)

std::string ddgi_settings_json(const DdgiSettings& s, const BackendChoice* ran_on) {
  nlohmann::json j = s;
  if (ran_on && ran_on->backend == Backend::Vulkan) {
    j["backend"] = backend_name(Backend::Vulkan);
    j["vulkan_device"] = ran_on->device.name;
    j["vulkan_driver"] = ran_on->device.driver;
  }
  j["gather"] = s.gather == Gather::Path ? "path" : "probes";
  j["light_sampling"] = s.light_sampling == LightSampling::Random ? "random" : "all";
  nlohmann::json suns = nlohmann::json::array();
  for (const SunLight& sun : s.suns)
    suns.push_back({{"direction", sun.direction}, {"lux", sun.lux}, {"color", sun.color}});
  j["suns"] = suns;
  j["closed_mesh_check"] = s.cgal_check;
  // Only when on, so that a bake without the filter keeps the bytes it had before the option.
  if (s.filter.enabled) j["probe_filter"] = {{"mode", "on"}, {"noise_k", s.filter.noise_k}};
  if (!s.irradiance_atlas) j["irradiance_atlas"] = false;  // likewise: only when left out
  if (s.depth_tile != kDepthTexels) j["depth_tile"] = s.depth_tile;  // likewise: only when coarsened
  if (s.near_surface_reach > 0.f) j["near_surface_reach"] = s.near_surface_reach;  // likewise
  if (s.fit.enabled)                                                 // likewise: only when on
    j["surface_fit"] = {{"directions", s.fit.directions},
                        {"gather", fit_gather_name(s.fit.gather)},
                        {"passes", s.fit.gather == FitGather::Both ? s.fit.passes : 1u},
                        {"paths", s.fit.paths},
                        {"max_samples", s.fit.max_samples},
                        {"reach", s.fit.reach},
                        {"lambda", s.fit.lambda},
                        {"roulette_depth", s.fit.roulette_depth},
                        {"read_cell", s.fit.read_cell},
                        {"relative_to_fit", s.fit.relative_to_fit}};
  return j.dump();
}

Status validate_ddgi_settings(const DdgiSettings& s) {
  if (s.rays < 1 || s.rays > (1u << 20)) return bad("--rays must be between 1 and 1048576");
  const int max_bounces = s.gather == Gather::Path ? kPathGatherBounces : kMaxProbeGatherBounces;
  if (s.bounces < 0 || s.bounces > max_bounces)
    return bad("--bounces must be between 0 and " + std::to_string(max_bounces) +
               (s.gather == Gather::Path ? "" : " with --gather probes"));
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
  if (!(s.near_surface_reach >= 0.f) || !std::isfinite(s.near_surface_reach))
    return bad("near-surface reach must be a non-negative number of metres");
  if (!(s.blend_cutoff >= 0.f && s.blend_cutoff <= 1.f)) return bad("--blend-cutoff must be in [0, 1]");
  if (!(s.filter.noise_k > 0.f) || !std::isfinite(s.filter.noise_k)) return bad("probe filter width must be positive");
  if (s.max_atlas_width < 18 || s.max_atlas_width > (1 << 20))
    return bad("--max-atlas-width must be between 18 and 1048576 texels");
  if (!valid_depth_tile(s.depth_tile)) return bad("--depth-tile must be 16, 8 or 4");
  if (s.fit.enabled && !s.irradiance_atlas)
    return bad("--surface-fit on fits the irradiance atlas, which --irradiance-atlas off leaves out");
  if (s.fit.directions < 1 || s.fit.directions > 1024) return bad("--fit-directions must be between 1 and 1024");
  if (s.fit.paths < 1 || s.fit.paths > (1u << 16)) return bad("--fit-paths must be between 1 and 65536");
  if (s.fit.roulette_depth < 0 || s.fit.roulette_depth > 64)
    return bad("the fit's roulette depth must be between 0 and 64");
  if (!(s.fit.read_cell >= 0.f && s.fit.read_cell <= 1.f))
    return bad("the fit's shared read cell must be between 0 and 1 probe spacing");
  if (!(s.fit.relative_to_fit >= 0.f && s.fit.relative_to_fit <= 1.f))
    return bad("the fit's residual must be relative to its light by between 0 and 1");
  if (s.fit.max_samples < 1 || s.fit.max_samples > (uint64_t(1) << 26))
    return bad("--fit-samples must be between 1 and 67108864");
  return Status::ok();
}

SetupSettings setup_settings(const DdgiSettings& s) {
  SetupSettings out;
  out.blend_cutoff = s.blend_cutoff;
  out.enclosure_resolution = s.enclosure_resolution;
  out.backend = s.backend;
  return out;
}

DdgiSettings with_ray_budget(const DdgiSettings& s, uint32_t ray_budget) {
  DdgiSettings out = s;
  if (ray_budget == 0) return out;
  if (s.target_error > 0.f) {
    out.ray_budget = s.ray_budget > 0 ? std::min(s.ray_budget, ray_budget) : ray_budget;
    out.rays = std::min(s.rays, std::max(1u, out.ray_budget / 2));
  } else {
    out.rays = std::min(s.rays, ray_budget);
  }
  return out;
}

uint32_t probe_ray_cap(const DdgiSettings& s) {
  if (!(s.target_error > 0.f)) return s.rays;
  return std::max(s.rays, s.max_rays ? s.max_rays : 8 * s.rays);
}

WorkloadEstimate ddgi_workload(const DdgiSettings& s, uint64_t probes, uint64_t triangles, int threads) {
  WorkloadEstimate w;
  w.probes = probes;
  // Adaptive bakes (--target-error) stop each probe between rays and the cap. With a ray budget
  // the batches go on until the budget is spent or every probe is below the target: taken as the
  // budget, what default bakes spend (they use up their budget, so twice the first batch would
  // underestimate them several times over). Without one: twice the first batch, within the cap.
  w.rays = std::min(2.0 * s.rays, double(probe_ray_cap(s)));
  if (s.target_error > 0.f && s.ray_budget > 0)
    w.rays = std::min(double(probe_ray_cap(s)), std::max(double(s.ray_budget), double(s.rays)));
  // Past the roulette depth a path gather's path survives with its throughput, which everyday
  // albedos keep low: its expected length is about the roulette depth and one more vertex, whatever
  // the bound (the model's fit used exactly that many). The probe gather's bounces are passes.
  w.bounces = s.gather == Gather::Path ? std::min(s.bounces, s.roulette_depth + 1) : s.bounces;
  w.relocation_rays = s.relocate ? uint64_t(s.relocate_rays) * uint64_t(std::max(s.relocate_iterations, 0)) : 0;
  w.triangles = triangles;
  w.threads = threads;
  return w;
}

}  // namespace gibake
