// `gibake info` (see bake_info.h).
#include "io/bakefile/bake_info.h"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "io/bakefile/bake_shard.h"
#include "io/bakefile/input_digest.h"
#include "io/bakefile/json_text.h"
#include "io/bakefile/vxgi_report.h"

namespace gibake {
namespace {

using nlohmann::json;

// Floats go into JSON as doubles: nlohmann prints the shortest round-tripping form, so the
// float value read back is bit-identical.
json vec3(const float* v) { return json::array({double(v[0]), double(v[1]), double(v[2])}); }

json section_json(const gibake_section_entry& s, uint32_t index) {
  return json{{"index", index},
              {"type", loader::section_type_name(s.type)},
              {"type_id", s.type},
              {"format", loader::element_format_name(s.format)},
              {"offset", s.offset},
              {"size", s.size},
              {"count", s.count},
              {"group", s.group},
              {"checksum", hash_text(s.checksum)}};
}

json probe_json(const loader::DdgiVolume& v, uint32_t index) {
  const std::array<int32_t, 3> c = v.probe_coord(index);
  const loader::Vec3 p = v.probe_position(index);
  json sh = json::array();
  for (uint32_t k = 0; k < v.sh_coefficients(); ++k)
    sh.push_back(json::array({double(v.sh(index, k, 0)), double(v.sh(index, k, 1)), double(v.sh(index, k, 2))}));
  json probe{{"index", index},
             {"coord", json::array({c[0], c[1], c[2]})},
             {"position", vec3(p.data())},
             {"state", probe_state_name(v.state(index))},
             {"sh", std::move(sh)}};
  if (v.has_stats()) {
    const gibake_probe_stats st = v.stats(index);
    probe["stats"] = json{{"rays", st.rays},
                          {"relative_error", double(st.relative_error)},
                          {"nearest_front", double(st.nearest_front)},
                          {"backface_fraction", double(st.backface_fraction)}};
  }
  return probe;
}

json volume_json(const loader::DdgiVolume& v, bool probes) {
  const gibake_ddgi_volume& d = v.desc();
  uint32_t active = 0, inactive = 0, sky_only = 0;
  for (uint32_t i = 0; i < v.probe_count(); ++i) {
    active += v.state(i) == GIBAKE_PROBE_ACTIVE;
    inactive += v.state(i) == GIBAKE_PROBE_INACTIVE;
    sky_only += v.state(i) == GIBAKE_PROBE_SKY_ONLY;
  }
  json out{{"grid_min", vec3(d.grid_min)},
           {"grid_max", vec3(d.grid_max)},
           {"spacing", vec3(d.spacing)},
           {"counts", json::array({d.counts[0], d.counts[1], d.counts[2]})},
           {"probe_count", d.probe_count},
           {"sh_order", d.sh_order},
           {"sh_coefficients", d.sh_coefficients},
           {"sh_format", loader::element_format_name(v.sh_format())},
           {"max_distance", double(d.max_distance)},
           {"units", {{"radiance", "cd/m2"}, {"irradiance", "lux"}, {"length", "m"}}},
           {"active_probes", active},
           {"inactive_probes", inactive},
           {"sky_only_probes", sky_only}};
  // A state the format does not define is counted apart, never as active (verify refuses it).
  if (active + inactive + sky_only < d.probe_count)
    out["undefined_state_probes"] = d.probe_count - active - inactive - sky_only;
  // A sparse volume's tiles lie in slot order, T a row; a dense one's by planes (format.h).
  const json layout =
      v.sparse() ? json{"tiles_per_row", d.atlas_tiles_per_row} : json{"planes_per_row", v.atlas_planes_per_row()};
  if (v.sparse()) out["stored_probes"] = d.stored_probes;
  if (v.has_irradiance())
    out["irradiance_atlas"] = {{"width", d.irradiance_width},
                               {"height", d.irradiance_height},
                               {"tile", d.irradiance_tile},
                               {"border", d.tile_border},
                               layout};
  if (v.has_depth())
    out["depth_atlas"] = {{"width", d.depth_width},
                          {"height", d.depth_height},
                          {"tile", d.depth_tile},
                          {"border", d.tile_border},
                          layout};
  if (probes) {
    json list = json::array();
    for (uint32_t i = 0; i < v.probe_count(); ++i) list.push_back(probe_json(v, i));
    out["probes"] = std::move(list);
  }
  return out;
}

json lpv_json(const loader::LpvCascade& c) {
  const gibake_lpv_cascade& d = c.desc();
  double flux[3] = {0, 0, 0};  // accumulated over iterations: sqrt(4 pi) * sum c0
  for (uint32_t i = 0; i < c.cell_count(); ++i)
    for (uint32_t k = 0; k < 3; ++k) flux[k] += 3.5449077018 * double(c.sh(i, k, 0));
  const float grid_max[3] = {d.grid_min[0] + float(d.dims[0]) * d.cell_size,
                             d.grid_min[1] + float(d.dims[1]) * d.cell_size,
                             d.grid_min[2] + float(d.dims[2]) * d.cell_size};
  return json{{"cascade_index", d.cascade_index},
              {"section", c.section()},
              {"grid_min", vec3(d.grid_min)},
              {"grid_max", vec3(grid_max)},
              {"cell_size", double(d.cell_size)},
              {"dims", json::array({d.dims[0], d.dims[1], d.dims[2]})},
              {"cell_count", d.cell_count},
              {"iterations", d.iterations},
              {"occlusion", (d.flags & GIBAKE_LPV_FLAG_OCCLUSION) != 0},
              {"sh_format", loader::element_format_name(c.sh_format())},
              {"units", {{"sh", "cd"}, {"irradiance", "lux"}, {"length", "m"}}},
              {"accumulated_flux_lm", json::array({flux[0], flux[1], flux[2]})}};
}

// The volume index (1.4): its grid and how long its lists are.
json index_json(const loader::DdgiVolumeIndex& index) {
  const gibake_ddgi_volume_index& d = index.desc();
  return json{{"section", index.section()},
              {"grid_min", vec3(d.grid_min)},
              {"cell_size", double(d.cell_size)},
              {"dims", json::array({d.dims[0], d.dims[1], d.dims[2]})},
              {"cell_count", d.cell_count},
              {"volume_count", d.volume_count},
              {"id_count", d.id_count},
              {"longest_list", d.longest}};
}

void print_index_text(const json& info, std::ostream& out) {
  if (!info.contains("ddgi_index")) return;
  const json& x = info["ddgi_index"];
  out << "ddgi volume index: " << x["dims"][0].get<int>() << "x" << x["dims"][1].get<int>() << "x"
      << x["dims"][2].get<int>() << " cells (" << x["cell_count"].get<uint32_t>() << ") of "
      << text_of(rounded_for_reading(x["cell_size"])) << " m, " << x["id_count"].get<uint32_t>()
      << " volume ids, longest list " << x["longest_list"].get<uint32_t>() << " of "
      << x["volume_count"].get<uint32_t>() << " volumes\n";
}

// A shard file (for gibake merge): which shard of which bake it holds.
void print_shard_text(const json& info, std::ostream& out) {
  if (!info.contains("shard")) return;
  const json& sh = info["shard"];
  out << "shard " << sh["index"].get<uint32_t>() << " of " << sh["count"].get<uint32_t>() << " (for gibake merge): probes ["
      << sh["probe_begin"].get<uint32_t>() << ", " << sh["probe_end"].get<uint32_t>() << ") of "
      << sh["probe_count"].get<uint32_t>() << ", gather " << sh["gather"].get<std::string>() << ", "
      << sh["bounce_hits"].get<uint64_t>() << " bounce hits, input hash " << sh["input_hash"].get<std::string>()
      << ", settings hash " << sh["settings_hash"].get<std::string>()
      << (sh["global_volumes"].get<bool>() ? ", carries the global volumes" : "") << "\n";
}

// Shown in text: positions rounded to what a person compares (the JSON keeps every digit).
std::string vec3_text(const float* v) { return text_of(rounded_for_reading(vec3(v))); }

void print_volumes_text(const loader::BakeFile& file, std::ostream& out) {
  size_t index = 0;
  for (const loader::DdgiVolume& v : file.ddgi_volumes()) {
    const gibake_ddgi_volume& d = v.desc();
    out << "ddgi volume " << index++ << ": " << d.counts[0] << "x" << d.counts[1] << "x" << d.counts[2] << " probes ("
        << d.probe_count << "), grid_min " << vec3_text(d.grid_min) << " grid_max " << vec3_text(d.grid_max)
        << " spacing " << vec3_text(d.spacing) << " m\n";
    out << "  SH order " << d.sh_order << " (" << d.sh_coefficients << " coefficients, "
        << loader::element_format_name(v.sh_format()) << ", radiance cd/m2), max distance "
        << text_of(rounded_for_reading(double(d.max_distance))) << " m\n";
    if (v.has_irradiance()) out << "  irradiance atlas " << d.irradiance_width << "x" << d.irradiance_height << " (lux)\n";
    if (v.has_depth()) out << "  depth atlas " << d.depth_width << "x" << d.depth_height << " (m, m^2)\n";
    if (v.sparse())
      out << "  sparse: " << d.stored_probes << " of " << d.probe_count << " probes stored, their tiles "
          << d.atlas_tiles_per_row << " a row in slot order\n";
    else if (v.has_irradiance() || v.has_depth())
      out << "  atlas layout: " << v.atlas_planes_per_row() << " of " << d.counts[1]
          << " Y-planes of tiles per band of rows\n";
    const json vj = volume_json(v, false);
    out << "  probes: " << vj["active_probes"].get<uint32_t>() << " active, " << vj["inactive_probes"].get<uint32_t>()
        << " inactive, " << vj["sky_only_probes"].get<uint32_t>() << " sky-only";
    if (vj.contains("undefined_state_probes"))
      out << ", " << vj["undefined_state_probes"].get<uint32_t>()
          << " of a state the format does not define (verify refuses the file)";
    out << "\n";
  }
}

void print_lpv_text(const json& info, std::ostream& out) {
  for (const json& c : info["lpv"]) {
    const json r = rounded_for_reading(c);
    out << "lpv cascade " << c["cascade_index"].get<uint32_t>() << ": " << c["dims"][0].get<int>() << "x"
        << c["dims"][1].get<int>() << "x" << c["dims"][2].get<int>() << " cells of " << text_of(r["cell_size"])
        << " m, grid_min " << text_of(r["grid_min"]) << " grid_max " << text_of(r["grid_max"]) << "\n";
    out << "  L1 SH of radiant intensity (cd, " << c["sh_format"].get<std::string>() << "), "
        << c["iterations"].get<uint32_t>() << " iterations accumulated, occlusion "
        << (c["occlusion"].get<bool>() ? "on" : "off") << ", accumulated flux " << text_of(r["accumulated_flux_lm"])
        << " lm\n";
  }
}

void print_probes_text(const loader::BakeFile& file, std::ostream& out) {
  size_t index = 0;
  for (const loader::DdgiVolume& v : file.ddgi_volumes()) {
    out << "ddgi volume " << index++ << " probes:\n";
    for (uint32_t i = 0; i < v.probe_count(); ++i) {
      const json p = probe_json(v, i);
      out << "  probe " << i << " coord " << text_of(p["coord"]) << " position "
          << text_of(rounded_for_reading(p["position"])) << " " << p["state"].get<std::string>();
      if (p.contains("stats"))
        out << " rays " << p["stats"]["rays"].get<uint32_t>() << " error " << text_of(p["stats"]["relative_error"]);
      out << " sh " << text_of(p["sh"]) << "\n";
    }
  }
}

// The summary first (volumes, cascades), then the file's sections, then the metadata (settings
// rounded and without placeholders), then every probe with --probes.
void print_text(const loader::BakeFile& file, const json& info, bool probes, std::ostream& out) {
  out << "version " << info["version"].get<std::string>() << ", " << file.size() << " bytes, input hash "
      << info["input_hash"].get<std::string>() << "\n";
  print_shard_text(info, out);
  print_volumes_text(file, out);
  print_index_text(info, out);
  print_lpv_text(info, out);
  if (info.contains("vxgi")) print_vxgi_info(info["vxgi"], out);
  out << "sections:\n";
  out << "  #  type             format        offset        size       count  checksum\n";
  for (const json& s : info["sections"]) {
    const std::string type = s["type"].get<std::string>();  // a name too long for its column keeps a space
    out << "  " << std::left << std::setw(3) << s["index"].get<int>() << std::setw(int(std::max<size_t>(17, type.size() + 1)))
        << type << std::setw(12) << s["format"].get<std::string>() << std::right
        << std::setw(8) << s["offset"].get<uint64_t>() << std::setw(12) << s["size"].get<uint64_t>()
        << std::setw(12) << s["count"].get<uint64_t>() << "  " << s["checksum"].get<std::string>() << "\n";
  }
  if (info.contains("metadata")) {
    json meta = rounded_for_reading(info["metadata"]);
    if (meta.is_object() && meta.contains("settings")) meta["settings"] = settings_for_reading(info["metadata"]["settings"]);
    out << "metadata: " << meta.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
  }
  if (probes) print_probes_text(file, out);
}

}  // namespace

const char* probe_state_name(uint32_t state) {
  switch (state) {
    case GIBAKE_PROBE_ACTIVE: return "active";
    case GIBAKE_PROBE_INACTIVE: return "inactive";
    case GIBAKE_PROBE_SKY_ONLY: return "sky-only";
    default: return "unknown";
  }
}

Status open_bake_file(const std::string& path, loader::BakeFile& file, bool verify_checksums, bool probe_major_tiles) {
  loader::LoadOptions options;
  options.verify_checksums = verify_checksums;
  options.probe_major_tiles = probe_major_tiles;
  const loader::Error e = file.open(path, options);
  if (!e) return Status::ok();
  if (e.code == loader::ErrorCode::IoError) return Status::io(path, e.message);
  return Status::invalid(path, loader::error_code_name(e.code), e.message);
}

json bake_info_json(const loader::BakeFile& file, bool probes) {
  const gibake_file_header& h = file.header();
  json info{{"version", std::to_string(h.version_major) + "." + std::to_string(h.version_minor)},
            {"file_size", h.file_size},
            {"input_hash", hash_text(h.input_hash)}};
  json sections = json::array();
  for (uint32_t i = 0; i < file.sections().size(); ++i) sections.push_back(section_json(file.sections()[i], i));
  info["sections"] = std::move(sections);
  const std::string meta = file.metadata_json();
  if (!meta.empty()) {
    json parsed = json::parse(meta, nullptr, false);
    info["metadata"] = parsed.is_discarded() ? json(meta) : parsed;
  }
  json volumes = json::array();
  for (const loader::DdgiVolume& v : file.ddgi_volumes()) volumes.push_back(volume_json(v, probes));
  info["ddgi"] = std::move(volumes);
  if (file.ddgi_index().present()) info["ddgi_index"] = index_json(file.ddgi_index());
  json cascades = json::array();
  for (const loader::LpvCascade& c : file.lpv_cascades()) cascades.push_back(lpv_json(c));
  info["lpv"] = std::move(cascades);
  json shard = shard_info_json(file);
  if (!shard.is_null()) info["shard"] = std::move(shard);
  if (!file.vxgi_volumes().empty()) {
    json vxgi = json::array();
    for (const loader::VxgiVolume& v : file.vxgi_volumes()) vxgi.push_back(vxgi_info_json(v));
    info["vxgi"] = std::move(vxgi);
  }
  return info;
}

Status bake_info(const std::string& path, const InfoOptions& options, std::ostream& out) {
  loader::BakeFile file;
  GIBAKE_TRY(open_bake_file(path, file));
  const json info = bake_info_json(file, options.probes);
  if (options.json) {
    out << info.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
  } else {
    out << path << ": gibake bake file\n";
    print_text(file, info, options.probes, out);
  }
  return Status::ok();
}

}  // namespace gibake
