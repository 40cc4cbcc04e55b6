// `gibake verify --scene`: the albedo bound of the energy check from the albedos the bakers really
// use, and the check that a bake of a lit scene is not black (see bake_verify.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "io/bakefile/bake_verify.h"
#include "io/scene.h"

namespace gibake::verify_detail {
namespace {

using nlohmann::json;

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// The brightest texel of a base-colour texture, per channel, linear (the bakers decode sRGB).
std::array<double, 3> max_texel(const Texture& t) {
  std::array<uint8_t, 3> top{0, 0, 0};
  for (size_t i = 0; i + 3 < t.rgba8.size(); i += 4)
    for (int k = 0; k < 3; ++k) top[size_t(k)] = std::max(top[size_t(k)], t.rgba8[i + size_t(k)]);
  return {srgb_to_linear(top[0] / 255.0), srgb_to_linear(top[1] / 255.0), srgb_to_linear(top[2] / 255.0)};
}

}  // namespace

double max_used_albedo(const Scene& scene) {
  std::vector<char> used(scene.materials.size(), 0);
  bool default_material = scene.materials.empty();
  for (int32_t m : scene.tri_material) {
    if (m < 0 || size_t(m) >= used.size()) default_material = true;
    else used[size_t(m)] = 1;
  }
  double albedo = default_material ? 1.0 : 0.0;  // the bakers' default material is white
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    if (!used[i]) continue;
    const Material& m = scene.materials[i];
    std::array<double, 3> texel{1.0, 1.0, 1.0};
    const int tex = m.base_color_texture.texture;
    if (tex >= 0 && size_t(tex) < scene.textures.size() && !scene.textures[size_t(tex)].rgba8.empty())
      texel = max_texel(scene.textures[size_t(tex)]);
    for (int k = 0; k < 3; ++k) albedo = std::max(albedo, double(m.base_color[k]) * texel[size_t(k)]);
  }
  double vertex = 1.0;  // COLOR_0 multiplies the albedo
  if (!scene.colors.empty()) {
    vertex = 0.0;
    for (size_t i = 0; i + 3 < scene.colors.size(); i += 4)
      for (int k = 0; k < 3; ++k) vertex = std::max(vertex, double(scene.colors[i + size_t(k)]));
  }
  return albedo * vertex;
}

void black_bake_check(const loader::BakeFile& file, const Scene& scene, const json& settings, double sky,
                      double sun_lux, VerifyReport& report) {
  std::vector<std::string> sources;
  if (!scene.lights.empty()) sources.push_back(std::to_string(scene.lights.size()) + " scene light(s)");
  if (sun_lux > 0.0) sources.push_back("--sun");
  if (sky > 0.0 || (settings.is_object() && settings.value("sky_hdr", std::string()) != "")) sources.push_back("a sky");
  for (const Material& m : scene.materials)
    if (m.is_emissive()) {
      sources.push_back("emissive materials");
      break;
    }
  if (file.ddgi_volumes().empty()) return;
  if (sources.empty()) {
    add(report, "lit", "skip", "the scene and settings bring no light: a black bake is what they give");
    return;
  }
  uint64_t sampled = 0, lit = 0;
  for (const loader::DdgiVolume& v : file.ddgi_volumes())
    for (uint32_t p = 0; p < v.probe_count(); ++p) {
      if (v.state(p) == GIBAKE_PROBE_INACTIVE) continue;
      ++sampled;
      bool any = false;
      for (uint32_t k = 0; k < v.sh_coefficients() && !any; ++k)
        for (uint32_t c = 0; c < 3 && !any; ++c) any = v.sh(p, k, c) != 0.f;
      lit += any;
    }
  std::string light;
  for (size_t i = 0; i < sources.size(); ++i) light += (i ? ", " : "") + sources[i];
  json details{{"sampled_probes", sampled}, {"lit_probes", lit}, {"light", light}};
  if (lit == 0)
    add(report, "lit", "fail",
        "black: " + std::string(sampled ? "every active probe reads zero" : "no probe is active") +
            " although the scene has light (" + light + "): the probes sit where no light reaches",
        details);
  else
    add(report, "lit", "pass", std::to_string(lit) + " of " + std::to_string(sampled) + " active probes see light",
        details);
}

}  // namespace gibake::verify_detail
