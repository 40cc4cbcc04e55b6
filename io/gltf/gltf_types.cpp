#include "io/gltf/gltf_types.h"

#include <cctype>
#include <cmath>
#include <cstring>
#include <vector>

namespace gibake::gltf {
namespace {

using nlohmann::json;

enum class Type { Object, Array, String, Number, Index, Bool };

struct Property {
  const char* name;
  Type type;
  bool required = false;
};

const char* expected(Type t) {
  switch (t) {
    case Type::Object: return "an object";
    case Type::Array: return "an array";
    case Type::String: return "a string";
    case Type::Number: return "a number";
    case Type::Index: return "a non-negative integer";
    case Type::Bool: return "true or false";
  }
  return "?";
}

bool has_type(const json& v, Type t) {
  switch (t) {
    case Type::Object: return v.is_object();
    case Type::Array: return v.is_array();
    case Type::String: return v.is_string();
    case Type::Number: return v.is_number();
    case Type::Index:  // 3.0 is read as 3, as glTF-Validator accepts it
      if (v.is_number_unsigned()) return true;
      if (v.is_number_integer()) return v.get<int64_t>() >= 0;
      return v.is_number_float() && v.get<double>() >= 0.0 && v.get<double>() == std::floor(v.get<double>());
    case Type::Bool: return v.is_boolean();
  }
  return false;
}

// A short rendering of the offending value for the message.
std::string shown(const json& v) {
  std::string text = v.dump();
  return text.size() > 40 ? text.substr(0, 37) + "..." : text;
}

struct Checker {
  const std::string& file;
  const Context& ctx;
  Status error;
  std::vector<std::string> warnings;  // printed only when there is no error

  static std::string join(const std::string& where, const std::string& name) {
    return where.empty() ? name : where + "." + name;
  }

  void problem(const std::string& where, const Property& p, const json& v) {
    const std::string what = std::string("expected ") + expected(p.type) + ", got " + shown(v);
    if (p.required) {
      if (error.is_ok()) error = Status::invalid(file, where, what);
      return;
    }
    warnings.push_back(file + ": " + where + ": " + what + "; ignored");
  }

  // The listed properties of `obj` (an object at `where`); a missing required one is left to the
  // importer, which names it.
  void properties(const json& obj, const std::string& where, std::initializer_list<Property> props) {
    for (const Property& p : props) {
      const auto it = obj.find(p.name);
      if (it != obj.end() && !has_type(*it, p.type)) problem(join(where, p.name), p, *it);
    }
    extensions(obj, where);
  }

  // Every extension's value is an object (KHR_texture_transform: "Not an object" is ignored).
  void extensions(const json& obj, const std::string& where) {
    const auto it = obj.find("extensions");
    if (it == obj.end()) return;
    if (!it->is_object()) return problem(join(where, "extensions"), {"extensions", Type::Object}, *it);
    for (auto e = it->begin(); e != it->end(); ++e)
      if (!e->is_object()) problem(join(where, "extensions." + e.key()), {"", Type::Object}, *e);
  }

  // A textureInfo (index required inside it) under a material.
  void texture_info(const json& parent, const std::string& where, const char* name) {
    const auto it = parent.find(name);
    if (it == parent.end() || !it->is_object()) return;
    properties(*it, join(where, name),
               {{"index", Type::Index}, {"texCoord", Type::Index}, {"scale", Type::Number}, {"strength", Type::Number}});
  }

  // `section` is a top-level array of objects; `each` checks one element.
  template <class F>
  void each(const json& doc, const char* section, F&& check) {
    const auto it = doc.find(section);
    if (it == doc.end() || !it->is_array()) return;
    for (size_t i = 0; i < it->size(); ++i) {
      const std::string where = std::string(section) + "[" + std::to_string(i) + "]";
      const json& item = (*it)[i];
      if (!item.is_object()) {
        problem(where, {"", Type::Object}, item);
        continue;
      }
      check(item, where);
    }
  }
};

void check_meshes(Checker& c, const json& doc) {
  c.each(doc, "meshes", [&](const json& mesh, const std::string& where) {
    c.properties(mesh, where, {{"name", Type::String}, {"primitives", Type::Array, true}, {"weights", Type::Array}});
    const auto prims = mesh.find("primitives");
    if (prims == mesh.end() || !prims->is_array()) return;
    for (size_t j = 0; j < prims->size(); ++j) {
      const std::string pw = where + ".primitives[" + std::to_string(j) + "]";
      const json& p = (*prims)[j];
      if (!p.is_object()) {
        c.problem(pw, {"", Type::Object, true}, p);
        continue;
      }
      c.properties(p, pw, {{"attributes", Type::Object, true}, {"indices", Type::Index}, {"material", Type::Index},
                           {"mode", Type::Index}, {"targets", Type::Array}});
    }
  });
}

void check_materials(Checker& c, const json& doc) {
  c.each(doc, "materials", [&](const json& m, const std::string& where) {
    c.properties(m, where, {{"name", Type::String}, {"pbrMetallicRoughness", Type::Object},
                            {"normalTexture", Type::Object}, {"occlusionTexture", Type::Object},
                            {"emissiveTexture", Type::Object}, {"emissiveFactor", Type::Array},
                            {"alphaMode", Type::String}, {"alphaCutoff", Type::Number}, {"doubleSided", Type::Bool}});
    for (const char* t : {"normalTexture", "occlusionTexture", "emissiveTexture"}) c.texture_info(m, where, t);
    const auto pbr = m.find("pbrMetallicRoughness");
    if (pbr == m.end() || !pbr->is_object()) return;
    const std::string pw = where + ".pbrMetallicRoughness";
    c.properties(*pbr, pw, {{"baseColorFactor", Type::Array}, {"baseColorTexture", Type::Object},
                            {"metallicFactor", Type::Number}, {"roughnessFactor", Type::Number},
                            {"metallicRoughnessTexture", Type::Object}});
    for (const char* t : {"baseColorTexture", "metallicRoughnessTexture"}) c.texture_info(*pbr, pw, t);
  });
}

// An accessor's componentType and type are among glTF's: the importer's parser would refuse them
// without saying which accessor.
void check_accessor_values(Checker& c, const json& a, const std::string& where) {
  const auto component = a.find("componentType");
  if (component != a.end() && component->is_number()) {
    const double t = component->get<double>();
    const bool known = t == 5120 || t == 5121 || t == 5122 || t == 5123 || t == 5125 || t == 5126;
    if (!known && c.error.is_ok())
      c.error = Status::invalid(c.file, Checker::join(where, "componentType"),
                                shown(*component) + " is not a glTF component type (5120-5123, 5125 or 5126)");
  }
  const auto type = a.find("type");
  if (type != a.end() && type->is_string()) {
    const std::string t = type->get<std::string>();
    const bool known =
        t == "SCALAR" || t == "VEC2" || t == "VEC3" || t == "VEC4" || t == "MAT2" || t == "MAT3" || t == "MAT4";
    if (!known && c.error.is_ok())
      c.error = Status::invalid(c.file, Checker::join(where, "type"),
                                shown(*type) + " is not a glTF accessor type (SCALAR, VEC2-4 or MAT2-4)");
  }
}

// glTF's image types. An image in a bufferView must name one; the bytes are decoded as what they
// are whatever it says, so a missing or other type is reported, not refused.
void check_mime_type(Checker& c, const json& im, const std::string& where) {
  const auto mime = im.find("mimeType");
  const bool in_view = im.find("bufferView") != im.end();
  if (mime == im.end()) {
    if (in_view)
      c.warnings.push_back(c.file + ": " + where +
                           ": an image in a bufferView has no mimeType (glTF requires image/png or image/jpeg); "
                           "decoded by its bytes");
    return;
  }
  if (!mime->is_string() || *mime == "image/png" || *mime == "image/jpeg") return;
  c.warnings.push_back(c.file + ": " + Checker::join(where, "mimeType") + ": " + shown(*mime) +
                       " is not image/png or image/jpeg; decoded by its bytes");
}

void check_data(Checker& c, const json& doc) {
  c.each(doc, "accessors", [&](const json& a, const std::string& where) {
    c.properties(a, where, {{"bufferView", Type::Index}, {"byteOffset", Type::Index},
                            {"componentType", Type::Index, true}, {"normalized", Type::Bool},
                            {"count", Type::Index, true}, {"type", Type::String, true}, {"max", Type::Array},
                            {"min", Type::Array}, {"sparse", Type::Object}, {"name", Type::String}});
    check_accessor_values(c, a, where);
  });
  c.each(doc, "bufferViews", [&](const json& v, const std::string& where) {
    c.properties(v, where, {{"buffer", Type::Index, true}, {"byteOffset", Type::Index},
                            {"byteLength", Type::Index, true}, {"byteStride", Type::Index}, {"target", Type::Index},
                            {"name", Type::String}});
    const auto stride = v.find("byteStride");
    if (stride != v.end() && stride->is_number()) {
      const double s = stride->get<double>();
      if (!(s >= 4 && s <= 252 && std::fmod(s, 4.0) == 0.0) && c.error.is_ok())
        c.error = Status::invalid(c.file, Checker::join(where, "byteStride"),
                                  shown(*stride) + " is not a glTF byte stride (a multiple of 4 from 4 to 252)");
    }
  });
  c.each(doc, "buffers", [&](const json& b, const std::string& where) {
    c.properties(b, where, {{"uri", Type::String}, {"byteLength", Type::Index, true}, {"name", Type::String}});
  });
  c.each(doc, "images", [&](const json& im, const std::string& where) {
    c.properties(im, where, {{"uri", Type::String}, {"mimeType", Type::String}, {"bufferView", Type::Index},
                             {"name", Type::String}});
    check_mime_type(c, im, where);
  });
  c.each(doc, "textures", [&](const json& t, const std::string& where) {
    c.properties(t, where, {{"sampler", Type::Index}, {"source", Type::Index}, {"name", Type::String}});
  });
  c.each(doc, "samplers", [&](const json& s, const std::string& where) {
    c.properties(s, where, {{"magFilter", Type::Index}, {"minFilter", Type::Index}, {"wrapS", Type::Index},
                            {"wrapT", Type::Index}, {"name", Type::String}});
  });
}

// A number glTF bounds above 0 where it is given. tinygltf reads an absent value and 0 alike, so
// a given 0 is only seen here, in the JSON.
bool given_not_positive(const json& obj, const char* name) {
  const auto it = obj.find(name);
  return it != obj.end() && it->is_number() && !(it->get<double>() > 0.0);
}

// KHR_lights_punctual's range, when given, is above 0 (without it a light reaches everywhere): a
// point or spot light's range of 0 is refused, as a negative one is by the importer. A directional
// light has no use for a range, so there it is only reported.
void check_light_ranges(Checker& c, const json& doc) {
  const auto ext = doc.find("extensions");
  if (ext == doc.end() || !ext->is_object()) return;
  const auto punctual = ext->find("KHR_lights_punctual");
  if (punctual == ext->end() || !punctual->is_object()) return;
  c.each(*punctual, "lights", [&](const json& light, const std::string& where) {
    if (!given_not_positive(light, "range")) return;
    const std::string at = "extensions.KHR_lights_punctual." + where + ".range";
    const auto type = light.find("type");
    if (type != light.end() && *type == "directional")
      c.warnings.push_back(c.file + ": " + at + ": " + shown(light["range"]) +
                           " is not above 0; a directional light has no range, ignored");
    else if (c.error.is_ok())
      c.error = Status::invalid(c.file, at,
                                shown(light["range"]) + " is not above 0 (leave range out for a light without one)");
  });
}

void check_scene_graph(Checker& c, const json& doc) {
  c.properties(doc, "", {{"asset", Type::Object}, {"scene", Type::Index}, {"scenes", Type::Array},
                             {"nodes", Type::Array}, {"meshes", Type::Array}, {"materials", Type::Array},
                             {"accessors", Type::Array}, {"bufferViews", Type::Array}, {"buffers", Type::Array},
                             {"textures", Type::Array}, {"images", Type::Array}, {"samplers", Type::Array},
                             {"cameras", Type::Array}, {"extensionsUsed", Type::Array},
                             {"extensionsRequired", Type::Array}});
  c.each(doc, "scenes", [&](const json& s, const std::string& where) {
    c.properties(s, where, {{"name", Type::String}, {"nodes", Type::Array}});
  });
  c.each(doc, "nodes", [&](const json& n, const std::string& where) {
    c.properties(n, where, {{"name", Type::String}, {"mesh", Type::Index}, {"camera", Type::Index},
                            {"skin", Type::Index}, {"children", Type::Array}, {"matrix", Type::Array},
                            {"translation", Type::Array}, {"rotation", Type::Array}, {"scale", Type::Array},
                            {"weights", Type::Array}});
  });
  c.each(doc, "cameras", [&](const json& cam, const std::string& where) {
    c.properties(cam, where, {{"type", Type::String, true}, {"perspective", Type::Object},
                              {"orthographic", Type::Object}, {"name", Type::String}});
    const auto persp = cam.find("perspective");
    if (persp != cam.end() && persp->is_object() && given_not_positive(*persp, "aspectRatio"))
      c.warnings.push_back(c.file + ": " + where + ".perspective.aspectRatio: " + shown((*persp)["aspectRatio"]) +
                           " is not above 0; the view's own aspect used");
  });
  check_light_ranges(c, doc);
}

}  // namespace

bool named_glb(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".glb";
}

// A .glb without the magic: say so, and what it looks like instead when that is plain.
std::string not_glb_text(const std::vector<unsigned char>& b) {
  auto starts = [&b](const char* sig, size_t n) { return b.size() >= n && std::memcmp(b.data(), sig, n) == 0; };
  if (b.empty()) return "not a GLB: the file is empty";
  std::string like;
  if (starts("\x89PNG", 4)) like = " (it is a PNG image)";
  else if (starts("\xff\xd8\xff", 3)) like = " (it is a JPEG image)";
  else if (!b.empty() && (b[0] == '{' || b[0] == ' ' || b[0] == '\n')) like = " (it looks like glTF JSON: name it .gltf)";
  return "not a GLB: bad magic (a GLB starts with 'glTF')" + like;
}

Status check_json_types(const std::string& file, const nlohmann::json& doc, const Context& ctx) {
  Checker c{file, ctx, Status::ok(), {}};
  check_scene_graph(c, doc);
  check_meshes(c, doc);
  check_materials(c, doc);
  check_data(c, doc);
  if (!c.error.is_ok()) return c.error;
  constexpr size_t kMaxWarnings = 20;  // a screenful; the rest as a count
  for (size_t i = 0; i < c.warnings.size() && i < kMaxWarnings; ++i) ctx.warning(c.warnings[i]);
  if (c.warnings.size() > kMaxWarnings)
    ctx.warning(file + ": " + std::to_string(c.warnings.size() - kMaxWarnings) +
                " more properties of the wrong type ignored");
  return Status::ok();
}

}  // namespace gibake::gltf
