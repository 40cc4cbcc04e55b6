#include "cli/bake_args.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace gibake::cli {

namespace {

// What to bake and where: the scene, the kinds, the files, threads and progress.
void add_output_options(CLI::App& sub, BakeArgs& a) {
  sub.add_option("scene", a.scene, "scene file (.gltf or .glb)")->required();
  sub.add_flag("--ddgi", a.ddgi, "bake DDGI probes");
  sub.add_option("--out,-o", a.out, "output bake file (with --ddgi and/or --lpv)");
  sub.add_flag("--lpv", a.lpv, "bake light propagation volume cascades into the bake file");
  sub.add_option("--voxels", a.voxels,
                 "voxelize the scene into this OpenVDB file (density, albedo, emission, normal, direct, aniso_*, "
                 "sdf, interior grids)");
  sub.add_option("--voxel-size", a.voxel_size, "voxel edge in metres (default: from --voxel-res)");
  sub.add_option("--voxel-res", a.voxel_res,
                 "voxels across the scene's longest side (default 128); the grid adds one empty voxel on every "
                 "side and one spare, so 128 gives 131 on that axis")
      ->check(whole_number(1, 1 << 20));
  sub.add_option("--voxel-sdf", a.voxel_sdf, "on|off: signed distance field grid 'sdf' (default on)");
  add_threads_option(&sub, a.threads, "results");
  sub.add_option("--progress", a.progress, "auto|bar|lines|json (stderr)");
}

// The probe grid, the rays and the light transport.
void add_probe_options(CLI::App& sub, BakeArgs& a) {
  sub.add_option("--probe-spacing", a.probe_spacing,
                 "probe spacing in metres (default: longest side / 24, within 0.25..1 m, widened to fit --probe-budget)")
      ->check(positive_number());
  sub.add_option("--probe-counts", a.probe_counts, "X,Y,Z probes per axis");
  sub.add_option("--grid-min", a.grid_min, "x,y,z of probe (0,0,0) (with --grid-max, --probe-counts)");
  sub.add_option("--grid-max", a.grid_max, "x,y,z of the last probe");
  sub.add_option("--grid-padding", a.padding, "metres added around the scene bounds (default 0)");
  sub.add_option("--probe-budget", a.probe_budget,
                 "most probes the default spacing rule places (default 32768; not with --probe-spacing/--probe-counts)")
      ->check(whole_number(1, INT64_MAX));
  sub.add_option("--probe-volume", a.probe_volumes,
                 "another probe volume minx,miny,minz:maxx,maxy,maxz[:spacing] (metres; default spacing: the rule on "
                 "its box within a share of --probe-budget); repeatable");
  sub.add_option("--default-volume", a.default_volume, "on|off: the default grid over the scene (default on)");
  sub.add_option("--detail-volumes", a.detail_volumes,
                 "auto|off: a finer volume around raised geometry the default grid is much too coarse for, e.g. a "
                 "building on a large ground (default auto)");
  sub.add_option("--max-probes", a.max_probes, "refuse grids with more probes (default 2097152)")
      ->check(whole_number(0, INT64_MAX));
  sub.add_option("--rays", a.rays, "rays per probe per batch (default 512)")->check(whole_number(1, 1 << 20));
  sub.add_option("--max-rays", a.max_rays, "per-probe ray cap with --target-error (default 8 x --rays)")
      ->check(whole_number(0, 1 << 24));
  sub.add_option("--target-error", a.target_error,
                 "more batches of --rays for a probe until the relative standard error of its mean radiance is below "
                 "this, at most --max-rays (default 0.05; 0: exactly --rays a probe)")
      ->check(CLI::Range(0.0, 1.0));
  sub.add_option("--ray-budget", a.ray_budget,
                 "with --target-error: rays per probe on average over each block of 512 probes (default 2048); "
                 "the batches after the first go to its noisiest probes first until it is spent (0: no budget)")
      ->check(whole_number(0, 1 << 24));
  sub.add_option("--seed", a.seed, "random seed (default 0)")->check(unsigned_integer());
  sub.add_option("--gather", a.gather,
                 "path|probes: light at ray hits from continued paths (converges to the path-traced truth) or "
                 "read back from the previous pass's probes (fast runtime approximation) (default path)");
  sub.add_option("--backend", a.backend,
                 "auto|cpu|vulkan (default auto: a discrete or integrated GPU when the cost model estimates it "
                 "faster for this bake, else the CPU; never lavapipe); vulkan demands a device (exit 4 without)");
  sub.add_option("--vulkan-device", a.vulkan_device,
                 "index or name from 'gibake info --devices', or lavapipe (Mesa's CPU device, only when named)");
  sub.add_option("--cache-dir", a.cache_dir,
                 "folder for GPU BVHs kept between bakes of the same geometry, or off (default $GIBAKE_CACHE_DIR, "
                 "else $XDG_CACHE_HOME/gibake, else ~/.cache/gibake; at most 1 GiB, least recently used removed)");
  sub.add_option("--bounces", a.bounces,
                 "indirect bounces: path vertices after the first hit, until roulette ends the path (default " +
                     std::to_string(kPathGatherBounces) + "); with --gather probes, passes (default " +
                     std::to_string(kProbeGatherBounces) + ")")
      ->check(whole_number(0, kPathGatherBounces));
  sub.add_option("--energy-conservation", a.energy_conservation, "indirect scale per bounce (default 1)");
  sub.add_option("--sh-order", a.sh_order, "1 or 2 (default 2)");
  sub.add_option("--light-sampling", a.light_sampling, "all|random (default all)");
}

// Sky and sun.
void add_light_options(CLI::App& sub, BakeArgs& a) {
  sub.add_option("--sky", a.sky, "constant sky radiance r,g,b in cd/m^2 (default black)");
  sub.add_option("--sky-hdr", a.sky_hdr, "equirect EXR sky (+Y up, centre column looks along -Z)");
  sub.add_option("--sky-hdr-scale", a.sky_hdr_scale, "multiplier for --sky-hdr values (default 1)");
  sub.add_option("--sun", a.suns,
                 "directional light dx,dy,dz:lux[:r,g,b]; d is the direction the light travels (0,-1,0 = from "
                 "straight above); repeatable");
}

// Probe relocation and classification, storage, the checks, the report and sharding.
void add_file_options(CLI::App& sub, BakeArgs& a) {
  sub.add_option("--relocate", a.relocate, "on|off (default on)");
  sub.add_option("--closed-mesh-check", a.closed_mesh_check,
                 "on|off: cross-check inactive probes against closed meshes with CGAL (default on)");
  sub.add_option("--blend-cutoff", a.blend_cutoff,
                 "alpha cutoff for alphaMode BLEND materials, which are traced as MASK (default 0.5; 0 = opaque)");
  sub.add_option("--max-atlas-width", a.max_atlas_width,
                 "widest atlas in texels; Y-planes of tiles wrap onto more rows to stay within it (default 16384)");
  sub.add_option("--depfile", a.depfile,
                 "also write a Makefile-style depfile listing the scene and every buffer/image read");
  sub.add_flag("--metadata-timings", a.metadata_timings,
               "record timings and the thread count in the file's metadata (the file then differs "
               "from run to run)");
  sub.add_option("--sh-format", a.sh_format, "f32|f16|auto: SH coefficient storage (default f32)");
  sub.add_option("--atlas-format", a.atlas_format,
                 "auto|f16|f32: atlas storage; auto = f16 when every value fits (default auto)");
  sub.add_option(
      "--leak-audit", a.leak_audit,
      "on|off: warn where a wall thinner than the probe spacing separates lit from unlit space (default on)");
  sub.add_option("--reconstruction-check", a.reconstruction_check,
                 "on|off: after a DDGI bake, compare the irradiance the loader's sampler reconstructs at surface "
                 "points with path-traced references and print the error (default on)");
  sub.add_option("--check-patches", a.check_patches, "4x4-point patches of the reconstruction check (default 128)")
      ->check(CLI::Range(1u, 1u << 20));
  sub.add_option("--check-rays", a.check_rays, "reference paths per point of the check (default 128)")
      ->check(CLI::Range(1u, 1u << 16));
  sub.add_option("--check-camera", a.check_cameras,
                 "the check's patches from this view instead of the probes' view: 'default' (preview's view), "
                 "'gltf:N' or ex,ey,ez,tx,ty,tz,ux,uy,uz; repeat for several views (they share the patches)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  sub.add_option("--check-fov", a.check_fov,
                 "vertical field of view of --check-camera views, degrees (default: the glTF camera's, else 50)");
  sub.add_option("--report", a.report,
                 "also write a self-contained HTML report (settings, timings, probe statistics, warnings, previews)");
  sub.add_option("--shard", a.shard,
                 "I/N: bake only shard I (from 0) of N of the probes into a shard file, for 'gibake merge'");
}

// Light propagation volumes.
void add_lpv_options(CLI::App& sub, BakeArgs& a) {
  sub.add_option("--lpv-res", a.lpv_res, "LPV cells on the longest axis of each cascade (default 32)");
  sub.add_option("--lpv-iterations", a.lpv_iterations,
                 "LPV propagation steps (default 0: the grid's longest axis)");
  sub.add_option("--lpv-cascades", a.lpv_cascades,
                 "nested LPV cascades, each twice the extent of the one inside it (default 1)");
  sub.add_option("--lpv-samples", a.lpv_samples,
                 "VPL rays per light, and VPLs on emissive triangles (default 65536)")
      ->check(whole_number(0, 0xffffffffLL));
}

}  // namespace

void add_bake_options(CLI::App& sub, BakeArgs& a) {
  sub.description("bake global illumination for a glTF scene");
  add_output_options(sub, a);
  add_probe_options(sub, a);
  add_light_options(sub, a);
  add_file_options(sub, a);
  add_lpv_options(sub, a);
  add_vxgi_options(&sub, a.vxgi);
  sub.add_option_function<uint64_t>("--max-memory", [&a](const uint64_t& v) { a.max_memory = a.vxgi.max_bytes = v; },
                                    "cap on any bake's estimated host memory: bytes or a size like 512M, 16G (default 16G)")
      ->check([](const std::string& v) { return v.find('-') == std::string::npos ? "" : "expected a size above 0"; })
      ->transform(CLI::AsSizeValue(false).description(""))
      ->check([](const std::string& v) { return v != "0" ? "" : "expected a size above 0"; })
      ->type_name("SIZE");
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

Status to_settings(const BakeArgs& a, DdgiSettings& s) {
  s.grid.padding = a.padding;
  s.grid.spacing = a.probe_spacing;
  s.grid.max_probes = a.max_probes;
  s.max_memory_bytes = a.max_memory;
  s.grid.auto_max_probes = a.probe_budget;
  if (!a.probe_counts.empty()) {
    std::vector<double> v;
    if (!parse_numbers(a.probe_counts, ',', 3, v)) return bad_arg("--probe-counts", "expected X,Y,Z");
    for (int i = 0; i < 3; ++i) {
      if (v[i] < 1 || v[i] > 1e6 || v[i] != std::floor(v[i]))
        return bad_arg("--probe-counts", "counts must be positive integers");
      s.grid.counts[i] = static_cast<int32_t>(v[i]);
    }
    if (a.probe_spacing > 0.f) return bad_arg("--probe-spacing", "give either --probe-spacing or --probe-counts");
  }
  if (!a.grid_min.empty() || !a.grid_max.empty()) {
    if (a.grid_min.empty() || a.grid_max.empty() || a.probe_counts.empty())
      return bad_arg("--grid-min", "--grid-min, --grid-max and --probe-counts go together");
    GIBAKE_TRY(parse_vec3("--grid-min", a.grid_min, s.grid.grid_min));
    GIBAKE_TRY(parse_vec3("--grid-max", a.grid_max, s.grid.grid_max));
    s.grid.explicit_bounds = true;
  }
  s.rays = a.rays;
  s.max_rays = a.max_rays;
  s.target_error = a.target_error;
  s.ray_budget = a.ray_budget;
  s.seed = a.seed;
  if (a.gather == "path") s.gather = Gather::Path;
  else if (a.gather == "probes") s.gather = Gather::Probes;
  else return bad_arg("--gather", "expected 'path' or 'probes'");
  s.bounces = a.bounces >= 0 ? a.bounces : s.gather == Gather::Path ? kPathGatherBounces : kProbeGatherBounces;
  GIBAKE_TRY(parse_backend_options(a.backend, a.vulkan_device, s.backend));
  s.backend.bvh_cache_dir = resolve_cache_dir(a.cache_dir);
  s.energy_conservation = a.energy_conservation;
  s.sh_order = a.sh_order;
  if (a.light_sampling == "all") s.light_sampling = LightSampling::All;
  else if (a.light_sampling == "random") s.light_sampling = LightSampling::Random;
  else return bad_arg("--light-sampling", "expected 'all' or 'random'");
  if (!a.sky.empty()) GIBAKE_TRY(parse_vec3("--sky", a.sky, s.sky));
  s.sky_hdr = a.sky_hdr;
  s.sky_hdr_scale = a.sky_hdr_scale;
  s.blend_cutoff = a.blend_cutoff;
  s.max_atlas_width = a.max_atlas_width;
  GIBAKE_TRY(parse_suns(a.suns, s.suns));
  GIBAKE_TRY(parse_on_off("--relocate", a.relocate, s.relocate));
  GIBAKE_TRY(parse_on_off("--closed-mesh-check", a.closed_mesh_check, s.cgal_check));
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

Status to_volume_settings(const BakeArgs& a, VolumeSettings& v) {
  GIBAKE_TRY(parse_on_off("--default-volume", a.default_volume, v.default_volume));
  if (a.detail_volumes != "auto" && a.detail_volumes != "off")
    return bad_arg("--detail-volumes", "expected auto or off, got '" + a.detail_volumes + "'");
  v.detail_volumes = a.detail_volumes == "auto";
  for (const std::string& text : a.probe_volumes) {
    const std::string expect = "expected minx,miny,minz:maxx,maxy,maxz[:spacing], got '" + text + "'";
    std::vector<std::string> parts;
    std::stringstream in(text);
    for (std::string part; std::getline(in, part, ':');) parts.push_back(part);
    if (parts.size() < 2 || parts.size() > 3 || text.back() == ':') return bad_arg("--probe-volume", expect);
    GivenVolume g;
    std::vector<double> lo, hi;
    if (!parse_numbers(parts[0], ',', 3, lo) || !parse_numbers(parts[1], ',', 3, hi))
      return bad_arg("--probe-volume", expect);
    for (int i = 0; i < 3; ++i) g.lo[i] = float(lo[i]), g.hi[i] = float(hi[i]);
    if (parts.size() == 3) {
      std::vector<double> s;
      if (!parse_numbers(parts[2], ',', 1, s) || !(s[0] > 0.0))
        return bad_arg("--probe-volume", "the spacing must be a positive number of metres, got '" + parts[2] + "'");
      g.spacing = float(s[0]);
    }
    v.given.push_back(g);
  }
  if (Status st = validate_volume_settings(v); !st) return bad_arg(v.given.empty() ? "--default-volume" : "--probe-volume", st.what());
  return Status::ok();
}

LpvSettings to_lpv_settings(const BakeArgs& a, const BackendSettings& backend) {
  LpvSettings s;
  s.resolution = a.lpv_res;
  s.iterations = a.lpv_iterations;
  s.cascades = a.lpv_cascades;
  s.vpl_samples = a.lpv_samples;
  s.emissive_samples = a.lpv_samples;
  s.seed = a.seed;
  s.backend = backend;
  s.max_memory_bytes = a.max_memory;
  return s;
}

}  // namespace gibake::cli
