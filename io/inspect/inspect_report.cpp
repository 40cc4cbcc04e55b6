// Builds the `gibake inspect` report (JSON or text) from a Scene and its mesh diagnostics.
#include "io/inspect/inspect_report.h"

#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

namespace gibake {

using json = nlohmann::ordered_json;  // keys in the order written

const char* alpha_mode_name(AlphaMode mode) {
  switch (mode) {
    case AlphaMode::Mask:
      return "MASK";
    case AlphaMode::Blend:
      return "BLEND";
    default:
      return "OPAQUE";
  }
}

const char* light_type_name(Light::Type type) {
  switch (type) {
    case Light::Type::Directional:
      return "directional";
    case Light::Type::Spot:
      return "spot";
    default:
      return "point";
  }
}

const char* light_intensity_unit(Light::Type type) {
  return type == Light::Type::Directional ? "lux" : "cd";
}

Status inspect_scene(const std::string& path, const InspectOptions& options, const Context& ctx,
                     InspectResult& out) {
  ImportOptions import_options;
  import_options.limits = options.limits;
  import_options.load_textures = options.load_textures;
  out = InspectResult{};
  GIBAKE_TRY(import_scene(path, import_options, ctx, out.scene));
  MeshDiagnosticsOptions diag_options;
  diag_options.check_self_intersections = options.check_self_intersections;
  ctx.report("diagnostics", 0, 1);
  out.diagnostics = diagnose_mesh(out.scene, diag_options);
  ctx.report("diagnostics", 1, 1);
  return Status::ok();
}

namespace {

// ---------------------------------------------------------------- JSON

json vec(const float* v, int n) {
  json a = json::array();
  for (int i = 0; i < n; ++i) a.push_back(v[i]);
  return a;
}

std::vector<uint64_t> triangles_per_material(const Scene& scene) {
  std::vector<uint64_t> counts(scene.materials.size(), 0);
  for (int32_t m : scene.tri_material)
    if (m >= 0 && size_t(m) < counts.size()) ++counts[size_t(m)];
  return counts;
}

json texture_ref_json(const Scene& scene, const TextureRef& ref) {
  if (ref.texture < 0) return nullptr;
  json j{{"texture", ref.texture}, {"texcoord", ref.texcoord}};
  if (size_t(ref.texture) < scene.textures.size())
    j["name"] = scene.textures[size_t(ref.texture)].name;
  if (ref.has_transform)
    j["transform"] = {
        {"offset", vec(ref.offset, 2)}, {"scale", vec(ref.scale, 2)}, {"rotation", ref.rotation}};
  return j;
}

json material_json(const Scene& scene, const Material& m, uint64_t triangles) {
  float radiance[3];
  for (int i = 0; i < 3; ++i) radiance[i] = m.emissive[i] * m.emissive_strength;
  json j{{"name", m.name},
         {"triangles", triangles},
         {"base_color", vec(m.base_color, 4)},
         {"metallic", m.metallic},
         {"roughness", m.roughness},
         {"emissive", m.is_emissive()},
         {"emissive_factor", vec(m.emissive, 3)},
         {"emissive_strength", m.emissive_strength},
         {"emissive_radiance", vec(radiance, 3)},
         {"emissive_radiance_unit", "cd/m2"},
         {"alpha_mode", alpha_mode_name(m.alpha_mode)},
         {"alpha_cutoff", m.alpha_cutoff},
         {"double_sided", m.double_sided}};
  j["textures"] = {{"base_color", texture_ref_json(scene, m.base_color_texture)},
                   {"emissive", texture_ref_json(scene, m.emissive_texture)}};
  return j;
}

json light_json(const Light& l) {
  json j{{"name", l.name},
         {"type", light_type_name(l.type)},
         {"intensity", l.intensity},
         {"unit", light_intensity_unit(l.type)},
         {"color", vec(l.color, 3)}};
  if (l.type != Light::Type::Directional) j["position"] = vec(l.position.data(), 3);
  if (l.type != Light::Type::Point) j["direction"] = vec(l.direction.data(), 3);
  if (l.type != Light::Type::Directional)
    j["range"] = l.range > 0.f ? json(l.range) : json(nullptr);
  if (l.type == Light::Type::Spot) {
    j["inner_cone_angle"] = l.inner_cone_angle;
    j["outer_cone_angle"] = l.outer_cone_angle;
  }
  return j;
}

json bounds_json(const Bounds& b) {
  if (b.empty()) return nullptr;
  const float size[3] = {b.max[0] - b.min[0], b.max[1] - b.min[1], b.max[2] - b.min[2]};
  return {{"min", vec(b.min.data(), 3)}, {"max", vec(b.max.data(), 3)}, {"size", vec(size, 3)}};
}

json diagnostics_json(const MeshDiagnostics& d) {
  json j{{"welded_vertices", d.welded_vertices},
         {"invalid_triangles", d.invalid_triangles},
         {"degenerate_triangles", d.degenerate_triangles},
         {"repeated_vertex_triangles", d.repeated_vertex_triangles},
         {"zero_area_triangles", d.zero_area_triangles},
         {"edges", d.edges},
         {"border_edges", d.border_edges},
         {"non_manifold_edges", d.non_manifold_edges},
         {"inconsistent_edges", d.inconsistent_edges},
         {"components", d.components},
         {"closed_components", d.closed_components},
         {"inward_closed_components", d.inward_closed_components},
         {"self_intersections_checked", d.self_intersections_checked}};
  const bool known = d.self_intersections_checked && d.self_intersections_complete;
  j["self_intersecting_pairs"] = known ? json(d.self_intersecting_pairs) : json(nullptr);
  return j;
}

json scene_json(const Scene& scene, const MeshDiagnostics& d) {
  const ImportStats& s = scene.stats;
  json j{{"file", scene.source_path},
         {"triangles", scene.triangle_count()},
         {"vertices", scene.vertex_count()},
         {"meshes", s.meshes},
         {"nodes", s.nodes},
         {"primitives", s.primitives},
         {"instances", scene.instances.size()},
         {"draco_primitives", s.draco_primitives},
         {"skipped_primitives", s.skipped_primitives},
         {"cameras", s.cameras},
         {"bounds", bounds_json(scene.bounds)}};
  const std::vector<uint64_t> per_material = triangles_per_material(scene);
  json materials = json::array();
  for (size_t i = 0; i < scene.materials.size(); ++i)
    materials.push_back(material_json(scene, scene.materials[i], per_material[i]));
  j["materials"] = std::move(materials);
  json textures = json::array();
  for (const Texture& t : scene.textures)
    textures.push_back({{"name", t.name},
                        {"width", t.width},
                        {"height", t.height},
                        {"wrap_s", t.wrap_s},
                        {"wrap_t", t.wrap_t},
                        {"decoded", !t.rgba8.empty()}});
  j["textures"] = std::move(textures);
  json lights = json::array();
  for (const Light& l : scene.lights) lights.push_back(light_json(l));
  j["lights"] = std::move(lights);
  j["diagnostics"] = diagnostics_json(d);
  return j;
}

// ---------------------------------------------------------------- text

std::string triple(const float* v) {
  std::ostringstream o;
  o << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return o.str();
}

void text_counts(std::ostream& o, const Scene& scene) {
  const ImportStats& s = scene.stats;
  o << "file: " << scene.source_path << "\n"
    << "triangles: " << scene.triangle_count() << "\n"
    << "vertices: " << scene.vertex_count() << "\n"
    << "meshes: " << s.meshes << ", nodes: " << s.nodes << ", primitives: " << s.primitives
    << " (instances " << scene.instances.size() << ", draco " << s.draco_primitives << ", skipped "
    << s.skipped_primitives << ")\n"
    << "cameras: " << s.cameras << "\n";
  if (scene.bounds.empty())
    o << "bounds: empty\n";
  else
    o << "bounds: min " << triple(scene.bounds.min.data()) << " max "
      << triple(scene.bounds.max.data()) << "\n";
}

void text_materials(std::ostream& o, const Scene& scene) {
  const std::vector<uint64_t> per_material = triangles_per_material(scene);
  o << "materials: " << scene.materials.size() << "\n";
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    o << "  [" << i << "] \"" << m.name << "\": " << per_material[i] << " triangles, "
      << alpha_mode_name(m.alpha_mode);
    if (m.alpha_mode == AlphaMode::Mask) o << " cutoff " << m.alpha_cutoff;
    o << (m.double_sided ? ", double-sided" : ", single-sided") << ", base colour "
      << triple(m.base_color);
    if (m.is_emissive()) {
      const float r[3] = {m.emissive[0] * m.emissive_strength, m.emissive[1] * m.emissive_strength,
                          m.emissive[2] * m.emissive_strength};
      o << ", emissive " << triple(r) << " cd/m2";
    }
    if (m.base_color_texture.texture >= 0)
      o << ", base colour texture " << m.base_color_texture.texture;
    if (m.emissive_texture.texture >= 0) o << ", emissive texture " << m.emissive_texture.texture;
    o << "\n";
  }
}

void text_textures_and_lights(std::ostream& o, const Scene& scene) {
  o << "textures: " << scene.textures.size() << "\n";
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    o << "  [" << i << "] \"" << t.name << "\": ";
    if (t.width > 0 && t.height > 0)
      o << t.width << "x" << t.height << "\n";
    else
      o << "size unknown\n";
  }
  o << "lights: " << scene.lights.size() << "\n";
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    o << "  [" << i << "] \"" << l.name << "\": " << light_type_name(l.type) << " " << l.intensity
      << " " << light_intensity_unit(l.type) << ", colour " << triple(l.color);
    if (l.type != Light::Type::Directional) o << ", position " << triple(l.position.data());
    if (l.type != Light::Type::Point) o << ", direction " << triple(l.direction.data());
    if (l.type != Light::Type::Directional && l.range > 0.f) o << ", range " << l.range;
    if (l.type == Light::Type::Spot)
      o << ", cones " << l.inner_cone_angle << ".." << l.outer_cone_angle << " rad";
    o << "\n";
  }
}

void text_diagnostics(std::ostream& o, const MeshDiagnostics& d) {
  o << "diagnostics:\n"
    << "  welded vertices: " << d.welded_vertices << "\n"
    << "  invalid triangles: " << d.invalid_triangles << "\n"
    << "  degenerate triangles: " << d.degenerate_triangles << " (repeated vertex "
    << d.repeated_vertex_triangles << ", zero area " << d.zero_area_triangles << ")\n"
    << "  edges: " << d.edges << " (border " << d.border_edges << ", non-manifold "
    << d.non_manifold_edges << ", inconsistently oriented " << d.inconsistent_edges << ")\n"
    << "  components: " << d.components << " (closed " << d.closed_components
    << ", of which inward-facing " << d.inward_closed_components << ")\n"
    << "  self-intersecting triangle pairs: ";
  if (!d.self_intersections_checked)
    o << "not checked (--check-self-intersections)\n";
  else if (!d.self_intersections_complete)
    o << "unknown (the check could not complete)\n";
  else
    o << d.self_intersecting_pairs << "\n";
}

}  // namespace

std::string inspect_report_json(const Scene& scene, const MeshDiagnostics& diagnostics) {
  return scene_json(scene, diagnostics).dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

std::string inspect_report_text(const Scene& scene, const MeshDiagnostics& diagnostics) {
  std::ostringstream o;
  text_counts(o, scene);
  text_materials(o, scene);
  text_textures_and_lights(o, scene);
  text_diagnostics(o, diagnostics);
  return o.str();
}

}  // namespace gibake
