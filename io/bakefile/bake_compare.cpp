// `gibake verify --against` and `--scene` checks (see bake_verify.h).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_match.h"
#include "io/bakefile/bake_verify.h"
#include "io/bakefile/vxgi_report.h"
#include "io/gltf/import.h"

namespace gibake::verify_detail {

using nlohmann::json;

void judge(VerifyReport& report, const std::string& name, const DiffStats& s, double tolerance,
           const std::string& item_label, const std::string& units) {
  json details{{"max_abs", s.max_abs}, {"rms", s.rms()}, {"values", s.count},
               {"worst_relative", s.worst_score}, {"units", units}};
  details["worst_" + item_label] = s.worst_item;
  const bool ok = s.worst_score <= tolerance;
  std::string message = "max abs " + std::to_string(s.max_abs) + " " + units + ", rms " + std::to_string(s.rms());
  if (!ok) message = item_label + " " + std::to_string(s.worst_item) + " differs beyond tolerance: " + message;
  add(report, name, ok ? "pass" : "fail", message, details);
}

namespace {

struct AtlasShape {
  bool present;
  uint32_t width, height;
};

// One atlas of both volumes ("irradiance" or "depth"): presence and size, then the first
// `channels` components of every texel (texel_of(volume, x, y)).
template <class TexelOf>
void compare_atlas(const loader::DdgiVolume& a, const loader::DdgiVolume& b, const std::string& kind,
                   const AtlasShape& sa, const AtlasShape& sb, int channels, TexelOf texel_of, const char* units,
                   const std::string& prefix, double tolerance, VerifyReport& report) {
  const std::string name = prefix + kind + "_atlas";
  if (sa.present != sb.present || sa.width != sb.width || sa.height != sb.height) {
    add(report, name, "fail", kind + " atlas presence or size differs");
    return;
  }
  if (!sa.present) return;
  DiffStats s;
  for (uint32_t y = 0; y < sa.height; ++y)
    for (uint32_t x = 0; x < sa.width; ++x) {
      const auto ta = texel_of(a, x, y), tb = texel_of(b, x, y);
      for (int k = 0; k < channels; ++k) s.add(ta[k], tb[k], int64_t(y) * sa.width + x);
    }
  judge(report, name, s, tolerance, "texel", units);
}

void compare_volume(const loader::DdgiVolume& a, const loader::DdgiVolume& b, const std::string& prefix,
                    const VerifyOptions& options, VerifyReport& report) {
  const gibake_ddgi_volume &da = a.desc(), &db = b.desc();
  const bool same_shape = std::equal(da.counts, da.counts + 3, db.counts) && da.sh_coefficients == db.sh_coefficients;
  if (!same_shape) {
    add(report, prefix + "structure", "fail", "probe counts or SH order differ from the reference");
    return;
  }
  // Probe p of both files stands at the same place only on the same grid: equal values elsewhere
  // light another part of the scene.
  if (!std::equal(da.grid_min, da.grid_min + 3, db.grid_min) ||
      !std::equal(da.grid_max, da.grid_max + 3, db.grid_max)) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "probe grid (%g, %g, %g) to (%g, %g, %g) differs from the reference's (%g, %g, %g) to (%g, %g, %g)",
                  double(da.grid_min[0]), double(da.grid_min[1]), double(da.grid_min[2]), double(da.grid_max[0]),
                  double(da.grid_max[1]), double(da.grid_max[2]), double(db.grid_min[0]), double(db.grid_min[1]),
                  double(db.grid_min[2]), double(db.grid_max[0]), double(db.grid_max[1]), double(db.grid_max[2]));
    add(report, prefix + "structure", "fail", text);
    return;
  }
  if (options.compare == "statistical") {
    compare_volume_statistical(a, b, prefix, options.statistical, report);
    return;
  }
  const double tolerance = options.tolerance;
  DiffStats sh, offsets;
  uint64_t state_mismatches = 0;
  int64_t first_state = -1;
  for (uint32_t p = 0; p < a.probe_count(); ++p) {
    for (const loader::Vec3& n : directions()) {
      const loader::Rgb ea = sh_irradiance_raw(a, p, n), eb = sh_irradiance_raw(b, p, n);
      for (int k = 0; k < 3; ++k) sh.add(ea[k], eb[k], p);
    }
    const loader::Vec3 oa = a.offset(p), ob = b.offset(p);
    for (int k = 0; k < 3; ++k) offsets.add(oa[k], ob[k], p);
    if (a.state(p) != b.state(p) && state_mismatches++ == 0) first_state = p;
  }
  judge(report, prefix + "sh_irradiance", sh, tolerance, "probe", "lux");
  judge(report, prefix + "offsets", offsets, tolerance, "probe", "m");
  if (state_mismatches)
    add(report, prefix + "states", "fail",
        std::to_string(state_mismatches) + " probe states differ, first probe " + std::to_string(first_state),
        {{"mismatches", state_mismatches}, {"worst_probe", first_state}});
  else
    add(report, prefix + "states", "pass", "probe states identical");
  // Atlases, texel by texel (irradiance RGB in lux, depth mean and mean^2).
  compare_atlas(a, b, "irradiance", {a.has_irradiance(), da.irradiance_width, da.irradiance_height},
                {b.has_irradiance(), db.irradiance_width, db.irradiance_height}, 3,
                [](const loader::DdgiVolume& v, uint32_t x, uint32_t y) { return v.irradiance_texel(x, y); }, "lux",
                prefix, tolerance, report);
  compare_atlas(a, b, "depth", {a.has_depth(), da.depth_width, da.depth_height},
                {b.has_depth(), db.depth_width, db.depth_height}, 2,
                [](const loader::DdgiVolume& v, uint32_t x, uint32_t y) { return v.depth_texel(x, y); }, "m, m^2",
                prefix, tolerance, report);
}

// LPV cascades: same grids, then irradiance at every cell centre for the 6 axis normals (lux).
void compare_lpv(const loader::BakeFile& a, const loader::BakeFile& b, double tolerance, VerifyReport& report) {
  if (a.lpv_cascades().size() != b.lpv_cascades().size()) {
    add(report, "against.lpv.structure", "fail", "number of LPV cascades differs from the reference",
        {{"cascades", a.lpv_cascades().size()}, {"reference", b.lpv_cascades().size()}});
    return;
  }
  static const loader::Vec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (size_t k = 0; k < a.lpv_cascades().size(); ++k) {
    const loader::LpvCascade& ca = a.lpv_cascades()[k];
    const loader::LpvCascade& cb = b.lpv_cascades()[k];
    const gibake_lpv_cascade &da = ca.desc(), &db = cb.desc();
    const std::string prefix = "against.lpv[" + std::to_string(k) + "].";
    bool same = da.cell_size == db.cell_size;
    for (int i = 0; i < 3; ++i) same = same && da.dims[i] == db.dims[i] && da.grid_min[i] == db.grid_min[i];
    if (!same) {
      add(report, prefix + "structure", "fail", "cascade grid (min, cell size or cell counts) differs from the reference");
      continue;
    }
    DiffStats stats;
    float sa[12], sb[12];
    for (uint32_t i = 0; i < ca.cell_count(); ++i) {
      ca.cell_sh(i, sa);
      cb.cell_sh(i, sb);
      for (const loader::Vec3& n : kAxes) {
        const loader::Rgb ea = ca.irradiance_from_sh(sa, n), eb = cb.irradiance_from_sh(sb, n);
        for (int c = 0; c < 3; ++c) stats.add(ea[size_t(c)], eb[size_t(c)], i);
      }
    }
    judge(report, prefix + "irradiance", stats, tolerance, "cell", "lux");
  }
}

json parse_metadata(const loader::BakeFile& file) {
  json meta = json::parse(file.metadata_json(), nullptr, false);
  return meta.is_object() ? meta : json::object();
}

// Largest sky radiance the settings declare (number or RGB array under a key containing "sky");
// returns false when the sky is a map whose maximum is unknown.
bool sky_bound(const json& settings, double& out) {
  out = 0.0;
  if (!settings.is_object()) return true;
  for (auto it = settings.begin(); it != settings.end(); ++it) {
    if (it.key().find("sky") == std::string::npos || it.key().find("scale") != std::string::npos) continue;
    const json& v = it.value();
    if (v.is_number()) out = std::max(out, v.get<double>());
    if (v.is_array())
      for (const json& e : v)
        if (e.is_number()) out = std::max(out, e.get<double>());
    if (v.is_string() && !v.get<std::string>().empty()) return false;
    if (v.is_object()) {
      double inner = 0.0;
      if (!sky_bound(v, inner)) return false;
      out = std::max(out, inner);
    }
  }
  return true;
}

// Directional lights the bake settings add to the scene ("suns": [{"lux", "color"}]), lux.
double settings_sun_lux(const json& settings) {
  double total = 0.0;
  if (!settings.is_object() || !settings.contains("suns") || !settings["suns"].is_array()) return 0.0;
  for (const json& sun : settings["suns"]) {
    if (!sun.is_object() || !sun.contains("lux") || !sun["lux"].is_number()) continue;
    double color = 1.0;
    if (sun.contains("color") && sun["color"].is_array()) {
      color = 0.0;
      for (const json& c : sun["color"])
        if (c.is_number()) color = std::max(color, c.get<double>());
    }
    total += sun["lux"].get<double>() * color;
  }
  return total;
}

void energy_check(const loader::BakeFile& file, const Scene& scene, const json& settings, VerifyReport& report) {
  const double suns = settings_sun_lux(settings);
  double sky = 0.0;
  const bool sky_known = sky_bound(settings, sky);
  black_bake_check(file, scene, settings, sky, suns, report);
  if (!sky_known) {
    add(report, "energy_bound", "skip", "sky map in the settings: radiance bound unknown");
    return;
  }
  double emissive = 0.0;
  for (const Material& m : scene.materials)
    for (int k = 0; k < 3; ++k) emissive = std::max(emissive, double(m.emissive[k]) * m.emissive_strength);
  double albedo = max_used_albedo(scene);  // of the triangles, textures and vertex colours included
  // Each bounce is scaled by the settings' energy_conservation (default 1).
  if (settings.is_object() && settings.contains("energy_conservation") && settings["energy_conservation"].is_number())
    albedo *= std::max(0.0, settings["energy_conservation"].get<double>());
  if (albedo >= 1.0) {
    add(report, "energy_bound", "skip", "albedo x energy_conservation >= 1: interreflection is unbounded");
    return;
  }
  double worst_ratio = 0.0;
  int64_t worst_probe = -1;
  for (const loader::DdgiVolume& v : file.ddgi_volumes()) {
    for (uint32_t p = 0; p < v.probe_count(); ++p) {
      if (v.state(p) == GIBAKE_PROBE_INACTIVE) continue;
      const loader::Vec3 pos = v.probe_position(p);
      double direct = suns;
      for (const Light& l : scene.lights) {
        const double c = std::max({l.color[0], l.color[1], l.color[2]}) * double(l.intensity);
        if (l.type == Light::Type::Directional) {
          direct += c;
          continue;
        }
        double d2 = 0.0;
        for (int k = 0; k < 3; ++k) d2 += double(pos[k] - l.position[k]) * double(pos[k] - l.position[k]);
        direct += c / std::max(d2, 1e-4);
      }
      const double bound = (direct + 3.14159265358979 * std::max(emissive, sky)) / (1.0 - albedo);
      const double slack = 1.1 + 3.0 * std::max(0.f, v.stats(p).relative_error);  // noise + SH overshoot
      double peak = 0.0;
      for (const loader::Vec3& n : directions())
        for (float e : v.sh_irradiance(p, n)) peak = std::max(peak, double(e));
      const double ratio = peak / std::max(bound * slack, 1e-30);
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst_probe = p;
      }
    }
  }
  json details{{"worst_ratio", worst_ratio}, {"probe", worst_probe}, {"max_albedo", albedo},
               {"max_emissive", emissive}, {"sky", sky}, {"lights", scene.lights.size()},
               {"settings_sun_lux", suns}};
  if (worst_ratio > 1.0)
    add(report, "energy_bound", "fail", "probe " + std::to_string(worst_probe) + " irradiance exceeds the scene's bound by " +
                                            std::to_string(worst_ratio) + "x", details);
  else
    add(report, "energy_bound", "pass", "irradiance within the lights' and emitters' bound", details);
}

// Whether the bake was made from the scene as it is now, naming what changed and in which file.
void staleness_check(const loader::BakeFile& file, const Scene& scene, const std::string& scene_path,
                     VerifyReport& report) {
  BakeSceneMatch m;
  if (const Status st = match_bake_to_scene(file, scene, m); !st) {
    add(report, "staleness", "fail", st.message());
    return;
  }
  json details{{"expected", hash_text(m.scene_hash)},
               {"recorded", hash_text(m.bake_hash)},
               {"hashed", m.by_content ? "content" : "file_bytes"},
               {"parts_changed", m.changes.parts},
               {"files_changed", m.changes.files_changed},
               {"files_added", m.changes.files_added},
               {"files_removed", m.changes.files_removed}};
  const std::string what = m.what();
  std::string message;
  if (m.matches)
    message = m.by_content ? "the scene's content and the settings are the bake's" +
                                 (what.empty() ? std::string() : "; " + what)
                           : "input hash matches the scene's files and the settings (a bake from before content "
                             "hashing: its hash is of the files' bytes)";
  else
    message = "stale: " + scene_path + ": " + what;
  add(report, "staleness", m.matches ? "pass" : "fail", message, details);
}

}  // namespace

void compare_files(const loader::BakeFile& a, const loader::BakeFile& b, const VerifyOptions& options,
                   VerifyReport& report) {
  if (a.ddgi_volumes().size() != b.ddgi_volumes().size()) {
    add(report, "against.structure", "fail", "number of DDGI volumes differs from the reference");
    return;
  }
  for (size_t i = 0; i < a.ddgi_volumes().size(); ++i)
    compare_volume(a.ddgi_volumes()[i], b.ddgi_volumes()[i], "against.ddgi[" + std::to_string(i) + "].", options,
                   report);
  // LPV and voxel GI record no noise of their own: value by value in either mode.
  compare_lpv(a, b, options.tolerance, report);
  compare_vxgi(a, b, options.tolerance, report);
}

void scene_checks(const loader::BakeFile& file, const std::string& scene_path, const Context& ctx,
                  VerifyReport& report) {
  Scene scene;
  const Status s = import_scene(scene_path, ImportOptions{}, ctx, scene);
  if (!s) {
    add(report, "scene", "fail", s.message());
    report.error = s.message();
    report.exit_code = static_cast<int>(s.code());
    return;
  }
  const json meta = parse_metadata(file);
  const json settings = meta.contains("settings") ? meta["settings"] : json();
  staleness_check(file, scene, scene_path, report);
  energy_check(file, scene, settings, report);
}

}  // namespace gibake::verify_detail
