#include "io/bakefile/vxgi_report.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "io/bakefile/json_text.h"

namespace gibake {
using nlohmann::json;
using verify_detail::add;

namespace {

// Calls f(level, face, x, y, z, texel) for every stored texel.
template <class F>
void for_texels(const loader::VxgiVolume& v, F&& f) {
  for (uint32_t l = 0; l < v.levels(); ++l) {
    const std::array<int32_t, 3> d = v.level_dims(l);
    for (uint32_t face = 0; face < v.faces(); ++face)  // the precomputed cone slices too
      for (int32_t z = 0; z < d[2]; ++z)
        for (int32_t y = 0; y < d[1]; ++y)
          for (int32_t x = 0; x < d[0]; ++x) f(l, face, x, y, z, v.texel(l, face, x, y, z));
  }
}

}  // namespace

json vxgi_info_json(const loader::VxgiVolume& v) {
  const gibake_vxgi_volume& d = v.desc();
  double peak = 0.0;
  uint64_t opaque = 0;
  const std::array<int32_t, 3> d0 = v.level_dims(0);
  for (int32_t z = 0; z < d0[2]; ++z)
    for (int32_t y = 0; y < d0[1]; ++y)
      for (int32_t x = 0; x < d0[0]; ++x) {
        float a = 0.f;
        for (uint32_t f = 0; f < 6; ++f) {
          const loader::Rgba t = v.texel(0, f, x, y, z);
          a = std::max(a, t[3]);
          if (t[3] > 0.f) peak = std::max(peak, double(std::max({t[0], t[1], t[2]}) / t[3]));
        }
        opaque += a > 0.f;
      }
  return {{"clipmap_index", d.clipmap_index},
          {"grid_min", {d.grid_min[0], d.grid_min[1], d.grid_min[2]}},
          {"voxel_size", d.voxel_size},
          {"dims", {d.dims[0], d.dims[1], d.dims[2]}},
          {"levels", d.levels},
          {"radiance_format", loader::element_format_name(v.radiance_format())},
          {"sdf", v.has_sdf()},
          {"precomputed_cones", d.faces > 6},
          {"sky", {d.sky[0], d.sky[1], d.sky[2]}},
          {"occupied_voxels", opaque},
          {"diffuse_scale", d.diffuse_scale},
          {"calibration_error", d.calibration_error},
          {"calibration_points", d.calibration_points},
          {"peak_radiance", peak}};
}

void print_vxgi_info(const json& volumes, std::ostream& out) {
  for (const json& c : volumes) {
    out << "vxgi volume " << c["clipmap_index"].get<uint32_t>() << ": " << c["dims"][0].get<int>() << "x"
        << c["dims"][1].get<int>() << "x" << c["dims"][2].get<int>() << " voxels of " << c["voxel_size"].get<double>()
        << " m, grid_min " << text_of(c["grid_min"]) << ", " << c["levels"].get<uint32_t>() << " mip levels\n";
    out << "  6 anisotropic faces (+X -X +Y -Y +Z -Z) of premultiplied radiance (cd/m^2, "
        << c["radiance_format"].get<std::string>() << "), " << c["occupied_voxels"].get<uint64_t>()
        << " occupied voxels, peak radiance " << c["peak_radiance"].get<double>() << " cd/m^2, sdf "
        << (c["sdf"].get<bool>() ? "yes" : "no")
        << (c["precomputed_cones"].get<bool>() ? ", 16 precomputed cone slices" : "") << "\n";
    out << "  diffuse scale " << c["diffuse_scale"].get<double>() << " (fitted to the path tracer at "
        << c["calibration_points"].get<uint32_t>() << " points, relative RMS " << c["calibration_error"].get<double>()
        << ")\n";
  }
}

void verify_vxgi(const loader::BakeFile& file, VerifyReport& report) {
  for (const loader::VxgiVolume& v : file.vxgi_volumes()) {
    const std::string prefix = "vxgi[" + std::to_string(v.desc().clipmap_index) + "].";
    uint64_t non_finite = 0, out_of_range = 0;
    std::string first;
    for_texels(v, [&](uint32_t l, uint32_t f, int32_t x, int32_t y, int32_t z, const loader::Rgba& t) {
      // The place's text only for the first failing texel: one for every texel costs more than the scan.
      auto where = [&] {
        return "level " + std::to_string(l) + " face " + std::to_string(f) + " voxel (" + std::to_string(x) + "," +
               std::to_string(y) + "," + std::to_string(z) + ")";
      };
      bool finite = true, range = true;
      for (float c : t) finite = finite && std::isfinite(c);
      if (!finite) {
        if (!non_finite++ && first.empty()) first = where();
        return;
      }
      range = t[3] >= -1e-3f && t[3] <= 1.001f && t[0] >= -1e-3f && t[1] >= -1e-3f && t[2] >= -1e-3f;
      if (!range && !out_of_range++ && first.empty()) first = where();
    });
    if (non_finite)
      add(report, prefix + "finite", "fail", std::to_string(non_finite) + " NaN/Inf texels, first at " + first);
    else
      add(report, prefix + "finite", "pass", "no NaN or Inf texels");
    if (out_of_range)
      add(report, prefix + "range", "fail",
          std::to_string(out_of_range) + " texels with alpha outside [0,1] or negative radiance, first at " + first);
    else
      add(report, prefix + "range", "pass", "alpha within [0,1], radiance >= 0");
  }
}

namespace {

// The empty-space distance (m) of every level-0 voxel, judged as the radiance is: what the cone
// tracer steps by, so a difference there moves every cone.
void compare_sdf(const loader::VxgiVolume& a, const loader::VxgiVolume& b, const std::string& prefix, double tolerance,
                 VerifyReport& report) {
  if (a.has_sdf() != b.has_sdf()) {
    add(report, prefix + "sdf", "fail",
        std::string("the distance field is ") + (a.has_sdf() ? "not " : "") + "in the reference but " +
            (a.has_sdf() ? "is" : "not") + " in this file");
    return;
  }
  if (!a.has_sdf()) return;
  verify_detail::DiffStats stats;
  const gibake_vxgi_volume& d = a.desc();
  int64_t voxel = 0;
  for (int32_t z = 0; z < d.dims[2]; ++z)
    for (int32_t y = 0; y < d.dims[1]; ++y)
      for (int32_t x = 0; x < d.dims[0]; ++x) stats.add(a.sdf_texel(x, y, z), b.sdf_texel(x, y, z), voxel++);
  verify_detail::judge(report, prefix + "sdf", stats, tolerance, "voxel", "m");
}

}  // namespace

void compare_vxgi(const loader::BakeFile& a, const loader::BakeFile& b, double tolerance, VerifyReport& report) {
  if (a.vxgi_volumes().empty() && b.vxgi_volumes().empty()) return;
  if (a.vxgi_volumes().size() != b.vxgi_volumes().size()) {
    add(report, "against.vxgi.structure", "fail", "number of voxel GI volumes differs from the reference",
        {{"volumes", a.vxgi_volumes().size()}, {"reference", b.vxgi_volumes().size()}});
    return;
  }
  for (size_t k = 0; k < a.vxgi_volumes().size(); ++k) {
    const loader::VxgiVolume &va = a.vxgi_volumes()[k], &vb = b.vxgi_volumes()[k];
    const gibake_vxgi_volume &da = va.desc(), &db = vb.desc();
    const std::string prefix = "against.vxgi[" + std::to_string(k) + "].";
    bool same = da.voxel_size == db.voxel_size && da.levels == db.levels;
    for (int i = 0; i < 3; ++i) same = same && da.dims[i] == db.dims[i] && da.grid_min[i] == db.grid_min[i];
    if (!same) {
      add(report, prefix + "structure", "fail", "voxel grid (min, size, counts or levels) differs from the reference");
      continue;
    }
    verify_detail::DiffStats stats;
    int64_t index = 0;
    for_texels(va, [&](uint32_t l, uint32_t f, int32_t x, int32_t y, int32_t z, const loader::Rgba& t) {
      const loader::Rgba r = vb.texel(l, f, x, y, z);
      for (int c = 0; c < 4; ++c) stats.add(t[size_t(c)], r[size_t(c)], index);
      ++index;
    });
    verify_detail::judge(report, prefix + "radiance", stats, tolerance, "texel", "cd/m^2");
    compare_sdf(va, vb, prefix, tolerance, report);
  }
}

}  // namespace gibake
