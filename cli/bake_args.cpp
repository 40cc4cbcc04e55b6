#include "cli/bake_args.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <sstream>

#include "bake/ddgi/volume_plan.h"
#include "cli/help.h"

namespace gibake::cli {

const std::vector<std::string> kQualityOptions{
    "--probe-spacing",    "--probe-counts", "--probe-budget", "--rays",          "--max-rays",
    "--ray-budget",       "--target-error", "--bounces",      "--refine-budget", "--refine-ray-budget",
    "--irradiance-atlas", "--depth-tile",   "--probe-filter", "--surface-fit",   "--fit-directions",
    "--fit-samples",      "--fit-paths",    "--fit-gather",   "--fit-solves",    "--fit-passes"};

namespace {

// A number as a user would write it ("0.5", "1e+20").
std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// Notes that the option was given, so that it wins over --quality's preset.
std::function<void(const std::string&)> given(BakeArgs& a, const char* name) {
  return [&a, name](const std::string&) {
    if (std::find(a.given.begin(), a.given.end(), name) == a.given.end()) a.given.emplace_back(name);
  };
}

bool was_given(const BakeArgs& a, const std::string& name) {
  return std::find(a.given.begin(), a.given.end(), name) != a.given.end();
}

// What to bake and which files to write.
void add_output_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Input and output");
  sub.add_option("SCENE", a.scene, "the scene: a .gltf or .glb file")->required()->group("Input and output");
  g.flag("--ddgi", a.ddgi, "bake DDGI probes into --out");
  g.flag("--lpv", a.lpv, "bake light propagation volume cascades into --out");
  g.flag("--vxgi", a.vxgi.enabled, "bake voxel GI volumes for cone tracing into --out");
  g.option("--out,-o", a.out, "FILE", "the bake file of --ddgi, --lpv and --vxgi (.gibake)");
  g.option("--voxels", a.voxels, "FILE", "voxelize the scene into this OpenVDB file (.vdb)");
  g.option("--report", a.report, "FILE", "also write a self-contained HTML report of a --ddgi bake");
  g.option("--depfile", a.depfile, "FILE", "also write a Makefile depfile: the scene and every file it reads");
}

// Where and how the bake runs; none of these changes the file's bytes but --backend and --shard.
// --max-memory's text: digits and an optional unit (b, or k m g t p e with i and b or not, each a
// power of 1024, as AsSizeValue(false) reads them), within 64 bits. Empty when it is one.
std::string size_text_error(const std::string& v) {
  const size_t digits = std::min(v.size(), v.find_first_not_of("0123456789"));
  std::string unit;
  for (size_t i = digits; i < v.size(); ++i)
    if (v[i] != ' ') unit += char(std::tolower(static_cast<unsigned char>(v[i])));
  const size_t power = unit.empty() || unit == "b" ? 0 : std::string("kmgtpe").find(unit[0]) + 1;
  const bool known = power == 0 ? unit.empty() || unit == "b"
                                : power <= 6 && (unit.size() == 1 || unit.substr(1) == "b" || unit.substr(1) == "i" ||
                                                 unit.substr(1) == "ib");
  if (digits == 0 || digits > 20 || !known) return "expected a size above 0 such as 512M or 16G, got '" + v + "'";
  if (std::stold(v.substr(0, digits)) * std::pow(1024.0L, int(power)) > 18446744073709551615.0L)
    return "expected a size within 16E (2^64 - 1 bytes), got '" + v + "'";
  return {};
}

void add_run_options(CLI::App& sub, BakeArgs& a) {
  const std::string group = "How it runs";
  OptionGroup g(sub, group);
  add_threads_option(&sub, a.threads, "results", group);
  g.option("--progress", a.progress, "MODE", "progress on stderr: auto, bar, lines or json")->capture_default_str();
  g.option("--backend", a.backend, "auto|cpu|vulkan", "where the bake runs; vulkan demands a GPU (exit 4)")
      ->capture_default_str();
  g.option("--vulkan-device", a.vulkan_device, "D", "an index or name from 'gibake info --devices', or lavapipe");
  g.option("--cache-dir", a.cache_dir, "DIR", "GPU BVHs kept between bakes, or off (unset: the user cache)");
  g.option("--shard", a.shard, "I/N", "bake only shard I (from 0) of N of the probes, for 'gibake merge'");
  g.option("--from-shards", a.from_shards, "PART...",
           "finish a --refine-by-check bake from its shards (in place of --shard)");
  sub.add_option_function<uint64_t>(
         "--max-memory", [&a](const uint64_t& v) { a.max_memory = a.vxgi.max_bytes = v; },
         "cap on a bake's estimated host memory: N, 512M, 16G")
      ->transform(CLI::AsSizeValue(false).description(""))
      // Transforms run newest first: the text is checked before AsSizeValue reads it, whose own
      // failures name its type or its arithmetic, not what the option takes.
      ->transform(CLI::Validator([](std::string& v) { return size_text_error(v); }, ""))
      ->check([](const std::string& v) { return v != "0" ? "" : "expected a size above 0, got '0'"; })
      ->group(group)
      ->option_text("SIZE")
      ->default_str("16G");
}

// Where the probes go: the default grid, given grids and volumes, relocation and classification.
void add_placement_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Probe placement");
  g.option("--probe-spacing", a.probe_spacing, "S", "metres between probes (unset: longest side / 24, see docs)")
      ->check(positive_number())
      ->each(given(a, "--probe-spacing"));
  g.option("--probe-counts", a.probe_counts, "X,Y,Z", "probes per axis (instead of --probe-spacing)")
      ->each(given(a, "--probe-counts"));
  g.option("--grid-min", a.grid_min, "X,Y,Z", "position of probe (0,0,0), with --grid-max and --probe-counts");
  g.option("--grid-max", a.grid_max, "X,Y,Z", "position of the last probe");
  g.option("--grid-padding", a.padding, "M", "metres added around the scene bounds")->capture_default_str();
  g.option("--probe-budget", a.probe_budget, "N", "most probes the default spacing rule places")
      ->check(whole_number(1, INT64_MAX))
      ->each(given(a, "--probe-budget"))
      ->capture_default_str();
  g.option("--max-probes", a.max_probes, "N", "refuse grids with more probes")
      ->check(whole_number(0, INT64_MAX))
      ->capture_default_str();
  g.option("--probe-volume", a.probe_volumes, "BOX",
           "a volume MIN:MAX[:S][:near] (near: probes by surfaces); repeatable");
  g.option("--near-camera", a.near_cameras, "VIEW", "fine probes by the surfaces this view sees; repeatable");
  g.option("--near-fov", a.near_fov, "DEG", "vertical field of view of --near-camera (unset: the glTF's)");
  g.option("--near-spacing", a.near_spacing, "M",
           "--near-camera volumes' spacing (unset: a quarter of the finest there)")
      ->each(given(a, "--near-spacing"));
  g.option("--default-volume", a.default_volume, "on|off", "the default grid over the scene")->capture_default_str();
  g.option("--detail-volumes", a.detail_volumes, "auto|off", "a finer volume around raised geometry where needed")
      ->capture_default_str();
  g.option("--refine-budget", a.refine_budget, "N", "probes in finer volumes where direct light changes")
      ->check(whole_number(0, INT64_MAX))
      ->each(given(a, "--refine-budget"))
      ->capture_default_str();
  g.option("--refine-ray-budget", a.refine_ray_budget, "N", "rays a refined probe averages (0 and cap: the grid's)")
      ->check(whole_number(0, 1 << 24))
      ->each(given(a, "--refine-ray-budget"))
      ->capture_default_str();
  g.option("--refine-by-check", a.refine_by_check, "N", "probes in finer volumes where the bake's check misses")
      ->check(whole_number(0, INT64_MAX))
      ->capture_default_str();
  g.option("--relocate", a.relocate, "on|off", "move probes away from nearby front faces")->capture_default_str();
  g.option("--closed-mesh-check", a.closed_mesh_check, "on|off", "confirm inactive probes in closed meshes (CGAL)")
      ->capture_default_str();
}

// How many rays, and how the light at their hits is gathered.
void add_ray_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Rays and light transport");
  g.option("--quality", a.quality, "draft|default|final", "spacing, budgets, rays and bounces; options win")
      ->capture_default_str();
  g.option("--rays", a.rays, "N", "rays per probe per batch")
      ->check(whole_number(1, 1 << 20))
      ->each(given(a, "--rays"))
      ->capture_default_str();
  g.option("--target-error", a.target_error, "E", "batches until a probe's relative error is under E")
      ->check(CLI::Range(0.0, 1.0))
      ->each(given(a, "--target-error"))
      ->capture_default_str();
  g.option("--max-rays", a.max_rays, "N", "a probe's ray cap with --target-error; 0: 8 x --rays")
      ->check(whole_number(0, 1 << 24))
      ->each(given(a, "--max-rays"))
      ->capture_default_str();
  g.option("--ray-budget", a.ray_budget, "N", "mean rays per probe for each 512-probe block; 0: none")
      ->check(whole_number(0, 1 << 24))
      ->each(given(a, "--ray-budget"))
      ->capture_default_str();
  g.option("--seed", a.seed, "N", "random seed")->check(unsigned_integer())->capture_default_str();
  g.option("--gather", a.gather, "path|probes", "light at ray hits: traced on, or read from the probes")
      ->capture_default_str();
  g.option("--bounces", a.bounces, "N", "path vertices after a hit; --gather probes: passes, 4")
      ->check(whole_number(0, kPathGatherBounces))
      ->each(given(a, "--bounces"))
      ->default_str(std::to_string(kPathGatherBounces));
  g.option("--energy-conservation", a.energy_conservation, "F", "scale on indirect light a pass (--gather probes)")
      ->each(given(a, "--energy-conservation"))
      ->capture_default_str();
  g.option("--light-sampling", a.light_sampling, "all|random", "a shadow ray to every light, or to one at random")
      ->capture_default_str();
  g.option("--probe-filter", a.probe_filter, "on|off",
           "average noise away over visible neighbouring probes [off; draft: on]")
      ->each(given(a, "--probe-filter"));
  g.option("--surface-fit", a.surface_fit, "on|off",
           "fit atlases to path-traced light on nearby surfaces [on; draft: off]")
      ->each(given(a, "--surface-fit"));
  g.option("--fit-directions", a.fit_directions, "N", "rays from each lit probe that find the fit's points [64]")
      ->check(whole_number(1, 1024))
      ->each(given(a, "--fit-directions"));
  g.option("--fit-samples", a.fit_samples, "N", "surface points the fit traces, at most [262144; final: 1048576]")
      ->check(whole_number(1, uint64_t(1) << 26))
      ->each(given(a, "--fit-samples"));
  g.option("--fit-paths", a.fit_paths, "N", "paths a surface point [144; final: 384]")
      ->check(whole_number(1, 1u << 16))
      ->each(given(a, "--fit-paths"));
  g.option("--fit-gather", a.fit_gather, "both|paths|probes", "fit paths: blended, whole, or probe-lit [default: both]")
      ->each(given(a, "--fit-gather"));
  g.option("--fit-solves", a.fit_solves, "1|2", "2: solve the fit again relative to its own light [2; final: 1]")
      ->check(whole_number(1, 2))
      ->each(given(a, "--fit-solves"));
  g.option("--fit-passes", a.fit_passes, "1|2", "2: end the paths in probes fitted to the whole paths [2; final: 1]")
      ->check(whole_number(1, 2))
      ->each(given(a, "--fit-passes"));
}

// Light the scene does not hold, and how its materials are traced.
void add_light_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Lights and materials");
  g.option("--sun", a.suns, "dx,dy,dz:lux[:r,g,b]", "directional light, d the way it travels; repeatable");
  g.option("--sky", a.sky, "R,G,B", "constant sky radiance, cd/m^2 (unset: black)");
  g.option("--sky-hdr", a.sky_hdr, "FILE", "equirectangular EXR sky, +Y up");
  g.option("--sky-hdr-scale", a.sky_hdr_scale, "F", "multiplier for --sky-hdr")
      ->check(non_negative_number())
      ->capture_default_str();
  g.option("--blend-cutoff", a.blend_cutoff, "C", "BLEND traced as MASK with this alpha cutoff; 0: opaque")
      ->capture_default_str();
}

// What the bake file stores, and how precisely.
void add_storage_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Storage");
  g.option("--sh-order", a.sh_order, "1|2", "SH bands a probe stores (1: 4 coefficients, 2: 9)")->capture_default_str();
  g.option("--sh-format", a.sh_format, "f32|f16|auto", "SH coefficient storage")->capture_default_str();
  g.option("--atlas-format", a.atlas_format, "FORMAT", "auto (f16 where it fits), f16, f32 or rgb9e5")
      ->capture_default_str();
  g.option("--max-atlas-width", a.max_atlas_width, "N", "widest atlas, texels; tiles wrap onto more rows")
      ->capture_default_str();
  g.option("--irradiance-atlas", a.irradiance_atlas, "on|off", "irradiance tiles for engines that read them [on]")
      ->each(given(a, "--irradiance-atlas"));
  g.option("--depth-tile", a.depth_tile, "16|8|4", "depth texels a tile side in the file [16; final: 8]")
      ->each(given(a, "--depth-tile"));
  g.flag("--metadata-timings", a.metadata_timings, "record timings in the file (which then differs run to run)");
}

// The checks that run after a bake.
void add_check_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Checks");
  g.option("--leak-audit", a.leak_audit, "on|off", "warn where a thin wall parts lit from unlit space")
      ->capture_default_str();
  g.option("--reconstruction-check", a.reconstruction_check, "on|off", "the file's irradiance against path tracing")
      ->capture_default_str();
  g.option("--check-patches", a.check_patches, "N", "4x4-point surface patches the check measures")
      ->check(CLI::Range(1u, 1u << 20))
      ->capture_default_str();
  g.option("--check-rays", a.check_rays, "N", "reference paths per point of the check")
      ->check(CLI::Range(1u, 1u << 16))
      ->capture_default_str();
  g.option("--check-noise", a.check_noise, "F", "trace patches noisier than this again; 0: one pass")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  g.option("--check-ray-budget", a.check_ray_budget, "N",
           "mean paths a point, both passes [device or views 32x; else 4x]")
      ->check(CLI::Range(0u, 1u << 20));
  g.option("--check-camera", a.check_cameras, "VIEW", "patches from this view: default, gltf:N or 9 numbers")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  g.option("--check-fov", a.check_fov, "DEG", "vertical field of view of --check-camera (unset: the glTF's)");
}

// The voxel grid of --voxels (the LPV's geometry volume too).
void add_voxel_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Voxels (--voxels, --lpv)");
  g.option("--voxel-res", a.voxel_res, "N", "voxels across the scene's longest side")
      ->check(whole_number(1, 1 << 20))
      ->default_str(std::to_string(VoxelSettings{}.resolution));
  g.option("--voxel-size", a.voxel_size, "M", "voxel edge in metres (instead of --voxel-res)");
  g.option("--voxel-sdf", a.voxel_sdf, "on|off", "also store the signed distance field grid 'sdf'")
      ->capture_default_str();
}

// Light propagation volumes.
void add_lpv_options(CLI::App& sub, BakeArgs& a) {
  OptionGroup g(sub, "Light propagation volumes (--lpv)");
  g.option("--lpv-res", a.lpv_settings.resolution, "N", "cells on each cascade's longest axis, 4 to 512")
      ->check(whole_number(4, 512))
      ->capture_default_str();
  g.option("--lpv-iterations", a.lpv_settings.iterations, "N",
           "propagation steps; 0: (longest axis)^2 / 4, at most 4096")
      ->check(whole_number(0, kMaxLpvIterations))
      ->capture_default_str();
  g.option("--lpv-cascades", a.lpv_settings.cascades, "K",
           "1 to 8 nested cascades, each twice the one inside")
      ->check(whole_number(1, 8))
      ->capture_default_str();
  g.option("--lpv-samples", a.lpv_settings.vpl_samples, "N", "VPL rays per light, and VPLs on emissive triangles")
      ->check(whole_number(1, 0xffffffffLL))
      ->capture_default_str();
}

}  // namespace

void add_bake_options(CLI::App& sub, BakeArgs& a) {
  sub.description("Bake global illumination for a glTF scene: DDGI probes, LPV, voxel GI, voxels");
  sub.footer(
      "Writes a bake file (--out) and/or an OpenVDB file (--voxels): give --ddgi, --lpv, --vxgi, --voxels.\n"
      "'gibake scene.gltf ...' is 'gibake bake scene.gltf ...'. Every option at length: docs/cli/bake.md");
  add_output_options(sub, a);
  add_run_options(sub, a);
  add_placement_options(sub, a);
  add_ray_options(sub, a);
  add_light_options(sub, a);
  add_storage_options(sub, a);
  add_check_options(sub, a);
  add_voxel_options(sub, a);
  add_lpv_options(sub, a);
  add_vxgi_options(&sub, a.vxgi);
}

std::string resolve_cache_dir(const std::string& option) {
  const auto env = [](const char* name) {
    const char* v = std::getenv(name);
    return std::string(v ? v : "");
  };
  std::string dir = option;
  if (dir.empty()) dir = env("GIBAKE_CACHE_DIR");
  if (dir.empty() && !env("XDG_CACHE_HOME").empty()) dir = env("XDG_CACHE_HOME") + "/gibake";
  if (dir.empty() && !env("HOME").empty()) dir = env("HOME") + "/.cache/gibake";
  return dir == "off" ? std::string() : dir;
}

bool parse_precision(const std::string& text, FloatPrecision& out) {
  if (text == "auto") out = FloatPrecision::Auto;
  else if (text == "f16") out = FloatPrecision::Half;
  else if (text == "f32") out = FloatPrecision::Full;
  else if (text == "rgb9e5")
    out = FloatPrecision::SharedExponent;
  else return false;
  return true;
}

Status parse_shard(const std::string& text, uint32_t& index, uint32_t& count) {
  unsigned long i = 0, n = 0;
  char slash = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%lu%c%lu%c", &i, &slash, &n, &extra) != 3 || slash != '/' || n < 1 || n > 65536 ||
      i >= n || text[0] == '-')
    return bad_arg("--shard", "expected I/N with 0 <= I < N <= 65536 (e.g. --shard 0/4), got '" + text + "'");
  index = uint32_t(i);
  count = uint32_t(n);
  return Status::ok();
}

Status parse_quality_option(const std::string& text, Quality& out) {
  if (parse_quality(text, out)) return Status::ok();
  const std::string close = closest_name(text, quality_names());
  return bad_arg("--quality", "expected draft, default or final, got '" + text + "'" +
                                  (close.empty() ? "" : "; did you mean '" + close + "'?"));
}

std::string quality_summary(const BakeArgs& a, const DdgiSettings& s, const VolumeSettings& v, float spacing) {
  Quality q = Quality::Default;
  if (!parse_quality(a.quality, q)) return {};
  std::vector<std::string> overridden;
  for (const std::string& name : kQualityOptions)
    if (was_given(a, name)) overridden.push_back(name);
  // The plan's own test (volume_plan.h), so that the line says what the bake did.
  const uint64_t refine = refines_default_grid(s.grid, v.refine) ? v.refine.budget : 0;
  return quality_text(q, s, spacing, overridden, refine, refine ? v.refine.ray_budget : 0);
}

namespace {

// A cap given below one batch cannot hold: every probe takes its first batch of --rays before any
// cap or budget applies. Refused rather than passed without a word; --rays given over a level's
// own cap or budget wins, as every option given over the level does.
Status check_ray_caps(const BakeArgs& a, const DdgiSettings& s) {
  if (!(s.target_error > 0.f)) return Status::ok();  // fixed rays: neither applies (bake.md says so)
  const std::string batch =
      " is under one batch of --rays " + std::to_string(s.rays) + ", which every probe takes first; ";
  if (was_given(a, "--max-rays") && s.max_rays != 0 && probe_ray_cap(s) != s.max_rays)
    return bad_arg("--max-rays", std::to_string(s.max_rays) + batch + "lower --rays or raise --max-rays");
  if (was_given(a, "--ray-budget") && s.ray_budget != 0 && s.ray_budget < s.rays)
    return bad_arg("--ray-budget", std::to_string(s.ray_budget) + batch +
                                       "lower --rays (to half the budget, so that adaptive rays place the rest)");
  return Status::ok();
}

}  // namespace

Status to_settings(const BakeArgs& a, DdgiSettings& s) {
  if (a.gather == "path") s.gather = Gather::Path;
  else if (a.gather == "probes") s.gather = Gather::Probes;
  else return bad_arg("--gather", "expected 'path' or 'probes', got '" + a.gather + "'");
  Quality quality = Quality::Default;
  GIBAKE_TRY(parse_quality_option(a.quality, quality));
  apply_quality(quality, s);  // then the options given over it
  if (was_given(a, "--probe-budget")) s.grid.auto_max_probes = a.probe_budget;
  if (was_given(a, "--rays")) s.rays = a.rays;
  if (was_given(a, "--max-rays")) s.max_rays = a.max_rays;
  if (was_given(a, "--target-error")) s.target_error = a.target_error;
  if (was_given(a, "--ray-budget")) s.ray_budget = a.ray_budget;
  if (was_given(a, "--bounces")) s.bounces = a.bounces;
  s.grid.padding = a.padding;
  s.grid.spacing = a.probe_spacing;
  s.grid.max_probes = a.max_probes;
  s.max_memory_bytes = a.max_memory;
  if (!a.probe_counts.empty()) {
    std::vector<double> v;
    const std::string expect = "expected three whole numbers X,Y,Z from 1 to 1000000, got '" + a.probe_counts + "'";
    if (!parse_numbers(a.probe_counts, ',', 3, v)) return bad_arg("--probe-counts", expect);
    for (int i = 0; i < 3; ++i) {
      if (v[i] < 1 || v[i] > 1e6 || v[i] != std::floor(v[i])) return bad_arg("--probe-counts", expect);
      s.grid.counts[i] = static_cast<int32_t>(v[i]);
    }
    if (a.probe_spacing > 0.f) return bad_arg("--probe-spacing", "give either --probe-spacing or --probe-counts");
  }
  if (!a.grid_min.empty() || !a.grid_max.empty()) {
    if (a.grid_min.empty() || a.grid_max.empty() || a.probe_counts.empty())
      return bad_arg("--grid-min", "--grid-min, --grid-max and --probe-counts go together");
    GIBAKE_TRY(parse_place("--grid-min", a.grid_min, s.grid.grid_min));
    GIBAKE_TRY(parse_place("--grid-max", a.grid_max, s.grid.grid_max));
    // Refused here, before the import: a box of no width along an axis of several probes would put
    // them all in one place (spacing 0), found only when the file is written.
    for (int i = 0; i < 3; ++i) {
      const float lo = s.grid.grid_min[size_t(i)], hi = s.grid.grid_max[size_t(i)];
      if (hi < lo || (hi == lo && s.grid.counts[size_t(i)] > 1))
        return bad_arg("--grid-max", std::string("must lie above --grid-min on every axis of more than one probe, and "
                                                 "not below it on any (axis ") +
                                         "xyz"[i] + ": " + number_text(lo) + " to " + number_text(hi) + ")");
    }
    s.grid.explicit_bounds = true;
  }
  s.seed = a.seed;
  GIBAKE_TRY(parse_backend_options(a.backend, a.vulkan_device, s.backend));
  s.backend.bvh_cache_dir = resolve_cache_dir(a.cache_dir);
  // A path gather traces the light it finds; the scale applies only to the probes' feedback passes.
  // Given without them it would be ignored by the bake, yet recorded (and used by verify's energy bound).
  if (was_given(a, "--energy-conservation") && s.gather != Gather::Probes)
    return bad_arg("--energy-conservation",
                   "scales the passes of --gather probes; a path gather traces every "
                   "bounce as it is: drop it, or add --gather probes");
  s.energy_conservation = a.energy_conservation;
  s.sh_order = a.sh_order;
  if (a.light_sampling == "all") s.light_sampling = LightSampling::All;
  else if (a.light_sampling == "random") s.light_sampling = LightSampling::Random;
  else return bad_arg("--light-sampling", "expected 'all' or 'random', got '" + a.light_sampling + "'");
  if (!a.sky.empty()) GIBAKE_TRY(parse_vec3("--sky", a.sky, s.sky));
  s.sky_hdr = a.sky_hdr;
  s.sky_hdr_scale = a.sky_hdr_scale;
  s.blend_cutoff = a.blend_cutoff;
  s.max_atlas_width = a.max_atlas_width;
  GIBAKE_TRY(parse_suns(a.suns, s.suns));
  GIBAKE_TRY(parse_on_off("--relocate", a.relocate, s.relocate));
  if (was_given(a, "--probe-filter")) GIBAKE_TRY(parse_on_off("--probe-filter", a.probe_filter, s.filter.enabled));
  if (was_given(a, "--surface-fit")) GIBAKE_TRY(parse_on_off("--surface-fit", a.surface_fit, s.fit.enabled));
  if (was_given(a, "--fit-directions")) s.fit.directions = a.fit_directions;
  if (was_given(a, "--fit-samples")) s.fit.max_samples = a.fit_samples;
  if (was_given(a, "--fit-paths")) s.fit.paths = a.fit_paths;
  // A second solve weighs each residual halfway to the first solve's fitted light (the default's).
  if (was_given(a, "--fit-solves"))
    s.fit.relative_to_fit = a.fit_solves == 2 ? SurfaceFitSettings{}.relative_to_fit : 0.f;
  if (was_given(a, "--fit-passes")) s.fit.passes = a.fit_passes;
  if (was_given(a, "--fit-gather") && !parse_fit_gather(a.fit_gather, s.fit.gather))
    return bad_arg("--fit-gather", "expected 'both', 'paths' or 'probes', got '" + a.fit_gather + "'");
  GIBAKE_TRY(parse_on_off("--closed-mesh-check", a.closed_mesh_check, s.cgal_check));
  if (was_given(a, "--irradiance-atlas"))
    GIBAKE_TRY(parse_on_off("--irradiance-atlas", a.irradiance_atlas, s.irradiance_atlas));
  if (was_given(a, "--depth-tile")) s.depth_tile = a.depth_tile;
  // The fit changes the irradiance atlas: without one (and not asked for) there is nothing to fit.
  if (!s.irradiance_atlas && !was_given(a, "--surface-fit")) s.fit.enabled = false;
  GIBAKE_TRY(check_ray_caps(a, s));
  return validate_ddgi_settings(s);
}
Status to_voxel_settings(const BakeArgs& a, VoxelSettings& v) {
  if (a.voxel_size != 0.f && a.voxel_res != 0)
    return bad_arg("--voxel-size", "give either --voxel-size or --voxel-res");
  if (a.voxel_size < 0.f || !std::isfinite(a.voxel_size))
    return bad_arg("--voxel-size", "must be a positive number of metres");
  v.voxel_size = a.voxel_size;
  if (a.voxel_res != 0) v.resolution = a.voxel_res;
  v.blend_cutoff = a.blend_cutoff;
  v.max_bytes = a.max_memory;
  return parse_on_off("--voxel-sdf", a.voxel_sdf, v.sdf);
}

namespace {

// --probe-budget bounds the volumes the spacing rule places: the default grid without a spacing or
// counts, the detail volume beside it, --probe-volume boxes without S. Given where none is, it
// would be ignored; refused instead.
Status check_probe_budget_used(const BakeArgs& a, const VolumeSettings& v) {
  if (!was_given(a, "--probe-budget")) return Status::ok();
  const bool ruled_grid = v.default_volume && !(a.probe_spacing > 0.f) && a.probe_counts.empty();
  const bool ruled_box =
      std::any_of(v.given.begin(), v.given.end(), [](const GivenVolume& g) { return !(g.spacing > 0.f); });
  if (ruled_grid || ruled_box) return Status::ok();
  return bad_arg(
      "--probe-budget",
      std::string("bounds only the probes the spacing rule places, and ") +
          (v.default_volume ? "--probe-spacing or --probe-counts sets the grid" : "--default-volume is off") +
          (v.given.empty() ? "" : " and every --probe-volume has its spacing") + "; drop it, or the spacing");
}

}  // namespace

Status to_volume_settings(const BakeArgs& a, VolumeSettings& v) {
  GIBAKE_TRY(parse_on_off("--default-volume", a.default_volume, v.default_volume));
  if (a.detail_volumes != "auto" && a.detail_volumes != "off")
    return bad_arg("--detail-volumes", "expected auto or off, got '" + a.detail_volumes + "'");
  v.detail_volumes = a.detail_volumes == "auto";
  Quality quality = Quality::Default;
  GIBAKE_TRY(parse_quality_option(a.quality, quality));
  // The level's budget refines the rule's grid (refine.h); a budget given refines any grid.
  v.refine.any_grid = was_given(a, "--refine-budget");
  v.refine.budget = v.refine.any_grid ? a.refine_budget : quality_preset(quality).refine_budget;
  v.refine.ray_budget =
      was_given(a, "--refine-ray-budget") ? a.refine_ray_budget : quality_preset(quality).refine_ray_budget;
  v.check_budget = a.refine_by_check;
  if (was_given(a, "--near-spacing")) {
    if (a.near_cameras.empty()) return bad_arg("--near-spacing", "spaces the probes of --near-camera volumes: add one");
    if (!(a.near_spacing >= kMinViewSpacing) || !std::isfinite(a.near_spacing)) {
      char got[64];
      std::snprintf(got, sizeof got, "expected a spacing of at least %g m, got %g", double(kMinViewSpacing),
                    double(a.near_spacing));
      return bad_arg("--near-spacing", got);
    }
    v.view_spacing = a.near_spacing;
  }
  for (const std::string& text : a.probe_volumes) {
    const std::string expect = "expected minx,miny,minz:maxx,maxy,maxz[:spacing][:near], got '" + text + "'";
    std::vector<std::string> parts;
    std::stringstream in(text);
    for (std::string part; std::getline(in, part, ':');) parts.push_back(part);
    GivenVolume g;
    if (parts.size() > 2 && parts.back() == "near") {
      g.near_surfaces = true;
      parts.pop_back();
    }
    if (parts.size() < 2 || parts.size() > 3 || text.back() == ':') return bad_arg("--probe-volume", expect);
    std::vector<double> lo, hi;
    if (!parse_numbers(parts[0], ',', 3, lo) || !parse_numbers(parts[1], ',', 3, hi))
      return bad_arg("--probe-volume", expect);
    GIBAKE_TRY(check_places("--probe-volume", lo, 0, 3, text));
    GIBAKE_TRY(check_places("--probe-volume", hi, 0, 3, text));
    for (int i = 0; i < 3; ++i) g.lo[i] = float(lo[i]), g.hi[i] = float(hi[i]);
    if (parts.size() == 3) {
      std::vector<double> s;
      // float(s) > 0: a spacing that underflows a float would read as 0, the spacing rule.
      if (!parse_numbers(parts[2], ',', 1, s) || !(float(s[0]) > 0.f))
        return bad_arg("--probe-volume", "the spacing must be a positive number of metres, got '" + parts[2] + "'");
      g.spacing = float(s[0]);
    }
    v.given.push_back(g);
  }
  if (Status st = validate_volume_settings(v); !st) return bad_arg(v.given.empty() ? "--default-volume" : "--probe-volume", st.what());
  return check_probe_budget_used(a, v);
}

Status check_refine_ray_budget(const BakeArgs& a, const DdgiSettings& s, const VolumeSettings& v) {
  if (!was_given(a, "--refine-ray-budget") || v.refine.ray_budget == 0 || v.refine.budget == 0) return Status::ok();
  // What the refined volumes would be traced with (planned_volume_settings' rule) against what was asked.
  const bool adaptive = s.target_error > 0.f;
  const DdgiSettings refined = with_ray_budget(s, v.refine.ray_budget);
  const uint32_t traced = adaptive ? refined.ray_budget : refined.rays;
  if (traced == v.refine.ray_budget) return Status::ok();
  const std::string grid = adaptive ? "--ray-budget" : "--rays";
  return bad_arg("--refine-ray-budget", "got " + std::to_string(v.refine.ray_budget) + ", over the grid's " + grid +
                                            " " + std::to_string(traced) +
                                            ": a refined probe takes at most the grid's rays; raise " + grid + " too");
}

LpvSettings to_lpv_settings(const BakeArgs& a, const BackendSettings& backend) {
  LpvSettings s = a.lpv_settings;
  s.emissive_samples = s.vpl_samples;  // --lpv-samples counts both
  s.seed = a.seed;
  s.backend = backend;
  s.max_memory_bytes = a.max_memory;
  return s;
}

}  // namespace gibake::cli
