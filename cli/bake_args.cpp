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

Status bad_arg(const std::string& option, const std::string& what) {
  return Status::error(ExitCode::BadArguments, "", option, what);
}

// "a,b,c" -> exactly n finite numbers.
bool parse_list(const std::string& text, size_t n, std::vector<double>& out) {
  out.clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(v)) return false;
      out.push_back(v);
    } catch (...) {
      return false;
    }
  }
  return out.size() == n;
}

Status parse_vec3(const std::string& option, const std::string& text, std::array<float, 3>& out) {
  std::vector<double> v;
  if (!parse_list(text, 3, v)) return bad_arg(option, "expected three numbers x,y,z, got '" + text + "'");
  for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(v[i]);
  return Status::ok();
}

// dx,dy,dz:lux[:r,g,b]
Status parse_sun(const std::string& text, SunLight& sun) {
  const size_t c1 = text.find(':');
  if (c1 == std::string::npos) return bad_arg("--sun", "expected dx,dy,dz:lux[:r,g,b], got '" + text + "'");
  const size_t c2 = text.find(':', c1 + 1);
  GIBAKE_TRY(parse_vec3("--sun", text.substr(0, c1), sun.direction));
  std::vector<double> lux;
  if (!parse_list(text.substr(c1 + 1, c2 == std::string::npos ? std::string::npos : c2 - c1 - 1), 1, lux) ||
      lux[0] < 0)
    return bad_arg("--sun", "illuminance (lux) must be a non-negative number in '" + text + "'");
  sun.lux = static_cast<float>(lux[0]);
  if (c2 != std::string::npos) GIBAKE_TRY(parse_vec3("--sun", text.substr(c2 + 1), sun.color));
  return Status::ok();
}

Status to_settings(const BakeArgs& a, DdgiSettings& s) {
  s.grid.padding = a.padding;
  s.grid.spacing = a.probe_spacing;
  s.grid.max_probes = a.max_probes;
  if (!a.probe_counts.empty()) {
    std::vector<double> v;
    if (!parse_list(a.probe_counts, 3, v)) return bad_arg("--probe-counts", "expected X,Y,Z");
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
  if (!parse_backend(a.backend, s.backend.backend)) return bad_arg("--backend", "expected 'auto', 'cpu' or 'vulkan'");
  if (!a.vulkan_device.empty() && s.backend.backend == Backend::Cpu)
    return bad_arg("--vulkan-device", "names a device for --backend vulkan or auto");
  s.backend.vulkan_device = a.vulkan_device;
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
  for (const std::string& text : a.suns) {
    SunLight sun;
    GIBAKE_TRY(parse_sun(text, sun));
    s.suns.push_back(sun);
  }
  if (a.relocate == "on") s.relocate = true;
  else if (a.relocate == "off") s.relocate = false;
  else return bad_arg("--relocate", "expected 'on' or 'off'");
  if (a.closed_mesh_check == "on") s.cgal_check = true;
  else if (a.closed_mesh_check == "off") s.cgal_check = false;
  else return bad_arg("--closed-mesh-check", "expected 'on' or 'off'");
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
  if (a.voxel_sdf == "on") v.sdf = true;
  else if (a.voxel_sdf == "off") v.sdf = false;
  else return bad_arg("--voxel-sdf", "expected 'on' or 'off'");
  return Status::ok();
}

LpvSettings to_lpv_settings(const BakeArgs& a) {
  LpvSettings s;
  s.resolution = a.lpv_res;
  s.iterations = a.lpv_iterations;
  s.cascades = a.lpv_cascades;
  s.vpl_samples = a.lpv_samples;
  s.emissive_samples = a.lpv_samples;
  s.seed = a.seed;
  parse_backend(a.backend, s.backend.backend);  // checked by to_settings
  s.backend.vulkan_device = a.vulkan_device;
  return s;
}

}  // namespace gibake::cli
