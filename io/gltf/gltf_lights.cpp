// Punctual lights.
#include "io/gltf/gltf_lights.h"

#include <cmath>
#include <cstdio>

#include "io/gltf/gltf_materials.h"
#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {
namespace {

// KHR_lights_punctual's cones: 0 <= inner < outer <= pi/2. Outside that the light is still
// defined, so the cones are brought into it and the change reported: the outer cone at most a
// hemisphere, the inner at most the outer (a hard edge).
void check_cones(const ImportEnv& env, const std::string& where, Light& l) {
  const float half_pi = 1.5707964f;
  auto said = [&](const char* what, float from, float to) {
    char text[160];
    std::snprintf(text, sizeof text, ".%s: %g rad is outside 0 <= innerConeAngle < outerConeAngle <= pi/2; %g used",
                  what, double(from), double(to));
    env.ctx->warning(env.file + ": " + where + text);
  };
  if (l.outer_cone_angle > half_pi) {
    said("outerConeAngle", l.outer_cone_angle, half_pi);
    l.outer_cone_angle = half_pi;
  }
  // glTF needs an outer cone above 0; at 0 or below the light shines nowhere. Kept (the file's
  // author may mean a light switched off), but said, as a bake lit by nothing else would be black.
  if (!(l.outer_cone_angle > 0.f)) {
    char text[160];
    std::snprintf(text, sizeof text, ".outerConeAngle: %g rad is not above 0; the spot light gives no light",
                  double(l.outer_cone_angle));
    env.ctx->warning(env.file + ": " + where + text);
    l.outer_cone_angle = l.inner_cone_angle = 0.f;
    return;
  }
  if (l.inner_cone_angle < 0.f || l.inner_cone_angle > l.outer_cone_angle) {
    const float to = l.inner_cone_angle < 0.f ? 0.f : l.outer_cone_angle;
    said("innerConeAngle", l.inner_cone_angle, to);
    l.inner_cone_angle = to;
  }
}

Status convert_light(const ImportEnv& env, size_t li, Light& out) {
  const auto& src = env.model->lights[li];
  std::string where = std::string("extensions.KHR_lights_punctual.") + at("lights", li);
  out.name = src.name;
  if (src.type == "directional") out.type = Light::Type::Directional;
  else if (src.type == "point") out.type = Light::Type::Point;
  else if (src.type == "spot") out.type = Light::Type::Spot;
  else return env.invalid(where, "unknown light type '" + src.type + "'");
  if (src.color.size() == 3)
    for (int k = 0; k < 3; ++k) out.color[k] = to_float(src.color[size_t(k)]);
  out.intensity = to_float(src.intensity);
  out.range = to_float(src.range);
  out.inner_cone_angle = to_float(src.spot.innerConeAngle);
  out.outer_cone_angle = to_float(src.spot.outerConeAngle);
  for (float v : {out.color[0], out.color[1], out.color[2], out.intensity, out.range, out.inner_cone_angle,
                  out.outer_cone_angle})
    if (!std::isfinite(v)) return env.invalid(where, "light has a non-finite value");
  if (out.intensity < 0.f || out.range < 0.f) return env.invalid(where, "negative intensity or range");
  for (int k = 0; k < 3; ++k)
    if (out.color[k] < 0.f) {
      char text[64];
      std::snprintf(text, sizeof text, ".color[%d]: %g is below 0; 0 used", k, double(out.color[k]));
      env.ctx->warning(env.file + ": " + where + text);
      out.color[k] = 0.f;
    }
  if (out.type == Light::Type::Spot) check_cones(env, where + ".spot", out);
  return Status::ok();
}

// The light index a node's KHR_lights_punctual extension names, or -1.
Status node_light(const ImportEnv& env, size_t node, int& light) {
  light = -1;
  const auto& ext = env.model->nodes[node].extensions;
  auto it = ext.find("KHR_lights_punctual");
  if (it == ext.end()) return Status::ok();
  double d = value_number(it->second.IsObject() ? it->second.Get("light") : tinygltf::Value(), -1.0);
  if (d < 0 || d >= double(env.model->lights.size()) || d != std::floor(d))
    return env.invalid(at("nodes", node), "KHR_lights_punctual.light index out of range");
  light = int(d);
  return Status::ok();
}

void place(const Mat4& w, Light& l) {
  for (int r = 0; r < 3; ++r) l.position[size_t(r)] = to_float(w[size_t(12 + r)]);
  double d[3];
  for (int r = 0; r < 3; ++r) d[r] = -w[size_t(8 + r)];  // world image of local -Z
  double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (len > 0 && std::isfinite(len))
    for (int r = 0; r < 3; ++r) l.direction[size_t(r)] = float(d[r] / len);
}

}  // namespace

Status import_lights(const ImportEnv& env, const std::vector<NodeInstance>& nodes, Scene& scene) {
  for (const auto& ni : nodes) {
    int li = -1;
    GIBAKE_TRY(node_light(env, size_t(ni.node), li));
    if (li < 0) continue;
    Light l;
    GIBAKE_TRY(convert_light(env, size_t(li), l));
    place(ni.world, l);
    for (float v : l.position)
      if (!std::isfinite(v)) return env.invalid(at("nodes", size_t(ni.node)), "light position is not finite");
    if (l.type != Light::Type::Directional)  // a directional light has no place
      GIBAKE_TRY(env.check_coordinates(at("nodes", size_t(ni.node)), "light position", l.position.data()));
    scene.lights.push_back(l);
  }
  return Status::ok();
}

}  // namespace gibake::gltf
