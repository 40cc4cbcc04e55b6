// Material and texture conversion.
#include "io/gltf/gltf_materials.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <utility>

#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {

double value_number(const tinygltf::Value& v, double fallback) {
  if (!v.IsNumber()) return fallback;
  double d = v.GetNumberAsDouble();
  return std::isfinite(d) ? d : fallback;
}

namespace {

float finite_or(double v, float fallback) {
  float f = to_float(v);
  return std::isfinite(f) ? f : fallback;
}

// A material factor as a float; one that is no finite float is replaced by `fallback`, and said so
// (the importer reports what it changes).
float factor(const ImportEnv& env, const std::string& where, double v, float fallback) {
  const float f = to_float(v);
  if (std::isfinite(f)) return f;
  char text[96];
  std::snprintf(text, sizeof text, ": %g is not a finite float; %g used", v, double(fallback));
  env.ctx->warning(env.file + ": " + where + text);
  return fallback;
}

// A factor glTF bounds to 0..1 (base colour): a value outside is clamped into it, and said so. An
// albedo above 1 reflects more light than arrives: over the paths' bounces the light grows without
// bound and overflows.
float unit_factor(const ImportEnv& env, const std::string& where, double v, float fallback) {
  const float f = factor(env, where, v, fallback);
  if (f >= 0.f && f <= 1.f) return f;
  const float clamped = f < 0.f ? 0.f : 1.f;
  char text[96];
  std::snprintf(text, sizeof text, ": %g is outside 0..1; %g used", double(f), double(clamped));
  env.ctx->warning(env.file + ": " + where + text);
  return clamped;
}

// A factor glTF bounds below by 0 (emission): a negative value is read as 0, and said so.
float non_negative_factor(const ImportEnv& env, const std::string& where, double v, float fallback) {
  const float f = factor(env, where, v, fallback);
  if (f >= 0.f) return f;
  char text[96];
  std::snprintf(text, sizeof text, ": %g is below 0; 0 used", double(f));
  env.ctx->warning(env.file + ": " + where + text);
  return 0.f;
}

// glTF's alphaMode (an enum, case-sensitive); any other value is read as OPAQUE, its default, and
// said so.
AlphaMode alpha_mode(const ImportEnv& env, const std::string& where, const std::string& mode) {
  if (mode == "MASK") return AlphaMode::Mask;
  if (mode == "BLEND") return AlphaMode::Blend;
  if (mode != "OPAQUE" && !mode.empty())
    env.ctx->warning(env.file + ": " + where + ".alphaMode: '" + mode + "' is not OPAQUE, MASK or BLEND; OPAQUE used");
  return AlphaMode::Opaque;
}

// `images` is the model's (pixels are moved out when `take`: no later texture uses the image).
Status import_texture(const ImportEnv& env, size_t i, std::vector<tinygltf::Image>& images, bool take, Texture& t) {
  const auto& m = *env.model;
  const auto& src = m.textures[i];
  std::string where = at("textures", i);
  t.name = src.name;
  if (src.sampler >= 0) {
    if (size_t(src.sampler) < m.samplers.size()) {
      const auto& s = m.samplers[size_t(src.sampler)];
      auto wrap = [](int w) { return (w == 33071 || w == 33648) ? w : 10497; };
      t.wrap_s = wrap(s.wrapS);
      t.wrap_t = wrap(s.wrapT);
    } else {
      env.ctx->warning(env.file + ": " + where + ": sampler index out of range; default sampler used");
    }
  }
  if (src.source < 0) {
    env.ctx->warning(env.file + ": " + where + ": no image source (extension-only textures are not decoded)");
    return Status::ok();
  }
  if (size_t(src.source) >= m.images.size()) {  // e.g. cornell-box-nvpro: geometry is still usable
    env.ctx->warning(env.file + ": " + where + ": image index out of range; texture ignored");
    return Status::ok();
  }
  auto& img = images[size_t(src.source)];
  if (img.width > 0 && img.height > 0) {
    t.width = img.width;
    t.height = img.height;
  }
  if (img.component == 4 && img.bits == 8 && img.image.size() == size_t(img.width) * size_t(img.height) * 4) {
    if (take) t.rgba8 = std::move(img.image);  // decoded textures are most of an import's memory
    else t.rgba8 = img.image;
  }
  return Status::ok();
}

// A material slot's texture reference with KHR_texture_transform.
Status texture_ref(const ImportEnv& env, const std::string& where, const tinygltf::TextureInfo& info,
                   const Scene& scene, TextureRef& ref) {
  if (info.index < 0) return Status::ok();
  if (size_t(info.index) >= scene.textures.size()) {
    env.ctx->warning(env.file + ": " + where + ": texture index out of range; texture ignored");
    return Status::ok();
  }
  ref.texture = scene.textures[size_t(info.index)].rgba8.empty() && !scene.textures[size_t(info.index)].width
                    ? -1
                    : info.index;
  ref.texcoord = info.texCoord;
  auto it = info.extensions.find("KHR_texture_transform");
  if (it != info.extensions.end() && it->second.IsObject()) {
    const auto& x = it->second;
    ref.has_transform = true;
    const auto& off = x.Get("offset");
    const auto& sc = x.Get("scale");
    for (int k = 0; k < 2; ++k) {
      if (off.IsArray() && off.ArrayLen() == 2) ref.offset[k] = finite_or(value_number(off.Get(k), 0.0), 0.f);
      if (sc.IsArray() && sc.ArrayLen() == 2) ref.scale[k] = finite_or(value_number(sc.Get(k), 1.0), 1.f);
    }
    ref.rotation = finite_or(value_number(x.Get("rotation"), 0.0), 0.f);
    double tc = value_number(x.Get("texCoord"), -1.0);
    if (tc >= 0.0 && tc < 64.0) ref.texcoord = int(tc);
  }
  if (ref.texcoord != 0)
    env.ctx->warning(env.file + ": " + where + ": uses TEXCOORD_" + std::to_string(ref.texcoord) +
                     "; only TEXCOORD_0 is carried");
  return Status::ok();
}

// A textureInfo inside an extension (tinygltf leaves it a Value): index, texCoord and its
// KHR_texture_transform. Index -1 when absent or not a non-negative integer.
tinygltf::TextureInfo texture_info_of(const tinygltf::Value& v) {
  tinygltf::TextureInfo info;
  if (!v.IsObject()) return info;
  const double index = value_number(v.Get("index"), -1.0), tc = value_number(v.Get("texCoord"), 0.0);
  info.index = index >= 0.0 && index < 2147483647.0 && index == std::floor(index) ? int(index) : -1;
  info.texCoord = tc >= 0.0 && tc < 64.0 ? int(tc) : 0;
  const tinygltf::Value& ext = v.Get("extensions");
  if (ext.IsObject() && ext.Has("KHR_texture_transform"))
    info.extensions["KHR_texture_transform"] = ext.Get("KHR_texture_transform");
  return info;
}

Status import_material(const ImportEnv& env, size_t i, const Scene& scene, Material& out) {
  const auto& src = env.model->materials[i];
  std::string where = at("materials", i);
  out.name = src.name;
  const auto& pbr = src.pbrMetallicRoughness;
  const std::string pbr_at = where + ".pbrMetallicRoughness";
  if (pbr.baseColorFactor.size() == 4)
    for (int k = 0; k < 4; ++k)
      out.base_color[k] =
          unit_factor(env, pbr_at + ".baseColorFactor[" + std::to_string(k) + "]", pbr.baseColorFactor[size_t(k)], 1.f);
  if (src.emissiveFactor.size() == 3)
    for (int k = 0; k < 3; ++k)
      out.emissive[k] = non_negative_factor(env, where + ".emissiveFactor[" + std::to_string(k) + "]",
                                            src.emissiveFactor[size_t(k)], 0.f);
  out.metallic = factor(env, pbr_at + ".metallicFactor", pbr.metallicFactor, 1.f);
  out.roughness = factor(env, pbr_at + ".roughnessFactor", pbr.roughnessFactor, 1.f);
  out.alpha_mode = alpha_mode(env, where, src.alphaMode);
  out.alpha_cutoff = factor(env, where + ".alphaCutoff", src.alphaCutoff, 0.5f);
  out.double_sided = src.doubleSided;
  auto es = src.extensions.find("KHR_materials_emissive_strength");
  if (es != src.extensions.end() && es->second.IsObject()) {
    out.emissive_strength =
        non_negative_factor(env, where + ".extensions.KHR_materials_emissive_strength.emissiveStrength",
                            value_number(es->second.Get("emissiveStrength"), 1.0), 1.f);
  }
  auto tr = src.extensions.find("KHR_materials_transmission");
  if (tr != src.extensions.end() && tr->second.IsObject()) {
    out.transmission = unit_factor(env, where + ".extensions.KHR_materials_transmission.transmissionFactor",
                                   value_number(tr->second.Get("transmissionFactor"), 0.0), 0.f);
    const tinygltf::TextureInfo info = texture_info_of(tr->second.Get("transmissionTexture"));
    GIBAKE_TRY(texture_ref(env, where + ".extensions.KHR_materials_transmission.transmissionTexture", info, scene,
                           out.transmission_texture));
  }
  GIBAKE_TRY(texture_ref(env, where + ".pbrMetallicRoughness.baseColorTexture", pbr.baseColorTexture, scene,
                         out.base_color_texture));
  GIBAKE_TRY(texture_ref(env, where + ".emissiveTexture", src.emissiveTexture, scene, out.emissive_texture));
  return Status::ok();
}

}  // namespace

// Material extensions the Lambertian bakers model only in part or not at all although they change
// where light goes: one warning per extension (not per material), naming how many materials use it.
void warn_ignored_transport_extensions(const ImportEnv& env) {
  static const std::pair<const char*, const char*> kIgnored[] = {
      {"KHR_materials_transmission",
       "traced as thin pass-through glass: transmissionFactor x transmissionTexture of the light goes straight on, "
       "tinted by the base colour; no refraction, IOR or roughness"},
      {"KHR_materials_diffuse_transmission", "traced as opaque: no light passes through thin surfaces"},
      {"KHR_materials_volume", "traced as opaque: no absorption or scattering inside the volume"},
      {"KHR_materials_pbrSpecularGlossiness", "its diffuse colour is not read: albedo from baseColor defaults"},
      {"KHR_materials_unlit",
       "lit as a diffuse surface of its base colour: it reflects the scene's light and emits none"},
  };
  const auto& materials = env.model->materials;
  for (const auto& [name, effect] : kIgnored) {
    size_t count = 0, first = 0;
    for (size_t i = 0; i < materials.size(); ++i)
      if (materials[i].extensions.count(name) && count++ == 0) first = i;
    if (count == 0) continue;
    const std::string& label = materials[first].name;
    const bool partial = std::string(name) == "KHR_materials_transmission";
    env.ctx->warning(env.file + ": " + name + (partial ? " is partly supported (" : " is not supported (") + std::to_string(count) +
                     (count == 1 ? " material, " : " materials, first ") + at("materials", first) +
                     (label.empty() ? "" : " '" + label + "'") + "): " + effect);
  }
}

Status import_materials(const ImportEnv& env, std::vector<tinygltf::Image>& images, Scene& scene) {
  const auto& m = *env.model;
  // The last texture that uses an image takes its pixels; earlier ones copy them.
  std::vector<size_t> last_user(images.size(), SIZE_MAX);
  for (size_t i = 0; i < m.textures.size(); ++i)
    if (m.textures[i].source >= 0 && size_t(m.textures[i].source) < images.size()) last_user[size_t(m.textures[i].source)] = i;
  scene.textures.resize(m.textures.size());
  for (size_t i = 0; i < m.textures.size(); ++i) {
    const int s = m.textures[i].source;
    const bool take = s >= 0 && size_t(s) < images.size() && last_user[size_t(s)] == i;
    GIBAKE_TRY(import_texture(env, i, images, take, scene.textures[i]));
  }
  scene.materials.resize(m.materials.size());
  for (size_t i = 0; i < m.materials.size(); ++i) GIBAKE_TRY(import_material(env, i, scene, scene.materials[i]));
  warn_ignored_transport_extensions(env);
  return Status::ok();
}

}  // namespace gibake::gltf
