#include "kernels/shade.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gibake::kernels {

ShadeLight make_shade_light(int type, const float color[3], float intensity, const float3& position,
                            const float3& direction, float range, float inner_cone, float outer_cone) {
  ShadeLight l;
  store3(l.position_range, position);
  l.position_range[3] = range;
  store3(l.direction_type, normalize(direction));
  l.direction_type[3] = static_cast<float>(type);
  for (int i = 0; i < 3; ++i) l.color[i] = color[i] * intensity;
  // KHR_lights_punctual: scale = 1/max(0.001, cos(inner)-cos(outer)), offset = -cos(outer)*scale.
  const float cos_outer = std::cos(outer_cone), cos_inner = std::cos(inner_cone);
  const float scale = 1.f / std::max(0.001f, cos_inner - cos_outer);
  l.cone[0] = scale;
  l.cone[1] = -cos_outer * scale;
  return l;
}

bool sample_light(const ShadeLight& light, const float3& p, LightSample& out) {
  const int type = static_cast<int>(light.direction_type[3]);
  const float3 travel = load3(light.direction_type);
  const float3 color = load3(light.color);
  if (type == kLightDirectional) {
    out.to_light = -travel;
    out.distance = std::numeric_limits<float>::infinity();
    out.illuminance = color;
  } else {
    const float3 v = load3(light.position_range) - p;
    const float d2 = dot(v, v);
    if (d2 <= 0.f) return false;
    const float d = std::sqrt(d2);
    out.to_light = v * (1.f / d);
    out.distance = d;
    float atten = 1.f / d2;
    const float range = light.position_range[3];
    if (range > 0.f) {
      const float r = d / range;
      atten *= clampf(1.f - r * r * r * r, 0.f, 1.f);  // glTF recommended range window
    }
    if (type == kLightSpot) {
      const float cd = dot(travel, -out.to_light);
      const float a = saturate(cd * light.cone[0] + light.cone[1]);
      atten *= a * a;
    }
    out.illuminance = color * atten;
  }
  return out.illuminance.x > 0.f || out.illuminance.y > 0.f || out.illuminance.z > 0.f;
}

float3 shade_direct(const float3& normal, const float3& albedo, const float3& emission,
                    const LightSample* samples, const float* visibility, int count, float scale) {
  float3 e{};
  for (int i = 0; i < count; ++i) {
    const float ndl = dot(normal, samples[i].to_light);
    if (ndl <= 0.f || visibility[i] <= 0.f) continue;
    e += samples[i].illuminance * (ndl * visibility[i]);
  }
  return emission + albedo * e * (scale / kPi);
}

float3 shade_indirect(const float3& albedo, const float3& indirect_irradiance, float energy_conservation) {
  return albedo * indirect_irradiance * (energy_conservation / kPi);
}

float3 shade_bounce(const HitRecord& hit, const float3& indirect_irradiance, float energy_conservation) {
  return load3(hit.radiance0) + load3(hit.albedo) * indirect_irradiance * (energy_conservation / kPi);
}

}  // namespace gibake::kernels
