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

// The four texels a bilinear texture read takes (RGBA8, row by row) and their weights.
struct BilinearTaps {
  const uint8_t* texel[4] = {};
  float weight[4] = {};
};

// A surface sample in two steps. begin_surface_sample computes all of it but the base colour's
// texels and starts their loads; finish_surface_sample reads them. Work between the two (a shadow
// ray) hides the texels' trip from memory, which at a random hit in a large texture costs about as
// much as the rest of the sample. The result is surface_sample's, bit for bit.
struct PendingSurface {
  SurfaceSample sample;  // its albedo without the base colour's texture until finished
  bool textured = false;
  BilinearTaps base_color;
};
PendingSurface begin_surface_sample(const Scene& scene, const TriangleShading& tri, float u, float v,
                                    const TextureFootprint& footprint);
SurfaceSample finish_surface_sample(const PendingSurface& pending);

// The packed record of triangle `tri` (PreparedScene keeps one for every triangle it traces).
TriangleShading triangle_shading(const Scene& scene, uint32_t tri);

}  // namespace gibake
