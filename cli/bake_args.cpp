#include "cli/bake_args.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace gibake::cli {

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
  s.seed = a.seed;
  s.bounces = a.bounces;
  if (a.gather == "path") s.gather = Gather::Path;
  else if (a.gather == "probes") s.gather = Gather::Probes;
  else return bad_arg("--gather", "expected 'path' or 'probes'");
  GIBAKE_TRY(parse_backend_options(a.backend, a.vulkan_device, s.backend));
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
  return parse_on_off("--voxel-sdf", a.voxel_sdf, v.sdf);
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
  return s;
}

}  // namespace gibake::cli
