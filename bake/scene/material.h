// Surface attributes at a triangle hit: base colour (factor x sRGB texture x COLOR_0), alpha,
// emission, interpolated normal. Barycentrics follow Embree: p = (1-u-v) v0 + u v1 + v v2.
#pragma once
#include <cstdint>

#include "bake/scene/texture_lod.h"
#include "bake/scene/triangle_shading.h"
#include "io/scene.h"
#include "kernels/vec.h"

namespace gibake {

struct SurfaceSample {
  kernels::float3 albedo;    // linear base colour (metallic/roughness ignored: Lambertian)
  kernels::float3 emission;  // cd/m^2
  kernels::float3 normal;    // interpolated vertex normal (unit, not yet oriented)
  float transmission = 0.f;  // Material::transmission x transmission texture red (linear)
  bool double_sided = false;
};

// Material of triangle `tri` (a default white, opaque, single-sided one for index -1).
const Material& triangle_material(const Scene& scene, uint32_t tri);

// The material of a packed record's triangle (the same as triangle_material of its index).
const Material& triangle_material(const Scene& scene, const TriangleShading& tri);

// Base-colour alpha (factor x texture alpha x vertex colour alpha) at (u, v) of triangle tri.
float surface_alpha(const Scene& scene, uint32_t tri, float u, float v);
float surface_alpha(const Scene& scene, const TriangleShading& tri, float u, float v);

// Alpha cutoff for masking, or a negative value when the material is opaque.
// BLEND is treated as MASK with cutoff `blend_cutoff` (0.5 by default; <= 0: opaque).
float alpha_cutoff_of(const Material& m, float blend_cutoff = kDefaultBlendCutoff);

SurfaceSample surface_sample(const Scene& scene, uint32_t tri, float u, float v);

// A ray's footprint where it lands: `width` metres across the ray (ray cone), `cos_theta` between
// ray and surface. With `lod`, colour and emission textures are read from the matching mip level.
struct TextureFootprint {
  const TextureLod* lod = nullptr;
  float width = 0.f;
  float cos_theta = 1.f;
};
SurfaceSample surface_sample(const Scene& scene, uint32_t tri, float u, float v, const TextureFootprint& footprint);
// The same from the triangle's packed record (the index forms above build one and call this).
SurfaceSample surface_sample(const Scene& scene, const TriangleShading& tri, float u, float v,
                             const TextureFootprint& footprint);

// The packed record of triangle `tri` (PreparedScene keeps one for every triangle it traces).
TriangleShading triangle_shading(const Scene& scene, uint32_t tri);

}  // namespace gibake
