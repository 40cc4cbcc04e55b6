// Hit shading for probe rays: Lambertian surfaces lit by KHR_lights_punctual lights (with
// shadow-ray visibility supplied by the caller), emission, sky for misses, and indirect
// irradiance from the previous bounce. Photometric units (DESIGN.md): lux, candela, cd/m^2.
#pragma once
#include <cstdint>

#include "kernels/vec.h"

namespace gibake::kernels {

enum LightType : int { kLightDirectional = 0, kLightPoint = 1, kLightSpot = 2 };

// std430-friendly: 4 x vec4.
struct ShadeLight {
  float position_range[4] = {0, 0, 0, 0};  // world position, range (0 = infinite)
  float direction_type[4] = {0, 0, -1, 0}; // unit direction the light travels, type (LightType)
  float color[4] = {0, 0, 0, 0};           // colour * intensity: lux (directional) or cd
  float cone[4] = {0, 0, 0, 0};            // spot: angle scale, angle offset (glTF formulation)
};

ShadeLight make_shade_light(int type, const float color[3], float intensity, const float3& position,
                            const float3& direction, float range, float inner_cone, float outer_cone);

// Light arriving at p: unit direction towards the light, distance for the shadow ray (infinity
// for directional) and illuminance on a surface facing the light (before n.l and visibility).
struct LightSample {
  float3 to_light;
  float distance = 0.f;
  float3 illuminance;
};
// False when the light contributes nothing at p (outside range or cone, zero intensity).
bool sample_light(const ShadeLight& light, const float3& p, LightSample& out);

// Per-ray record kept between bounces (4 x vec4 = 64 bytes).
enum HitKind : int { kHitMiss = 0, kHitFront = 1, kHitBack = 2 };
struct HitRecord {
  float dir_t[4] = {0, 0, 0, -1};        // ray direction, hit distance (-1 for a miss)
  float normal_kind[4] = {0, 0, 0, 0};   // shading normal facing the ray, HitKind
  float albedo[4] = {0, 0, 0, 0};        // Lambertian albedo (0 for misses and inside hits)
  float radiance0[4] = {0, 0, 0, 0};     // emission + direct light (or sky for a miss), cd/m^2
  int kind() const { return static_cast<int>(normal_kind[3]); }
};

// Emission + albedo/pi * scale * sum_i visibility_i * E_i * max(0, n.l_i).
float3 shade_direct(const float3& normal, const float3& albedo, const float3& emission,
                    const LightSample* samples, const float* visibility, int count, float scale);

// Indirect part of a hit's outgoing radiance: albedo/pi * energy * E_indirect.
float3 shade_indirect(const float3& albedo, const float3& indirect_irradiance, float energy_conservation);

// Outgoing radiance of a hit for bounce k: radiance0 + albedo/pi * energy * E_indirect.
float3 shade_bounce(const HitRecord& hit, const float3& indirect_irradiance, float energy_conservation);

}  // namespace gibake::kernels
