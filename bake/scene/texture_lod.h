// Mip chains of the scene's textures and each triangle's texel density, so a ray that lands far
// away (a probe ray, a path's bounce ray) reads the texture averaged over its footprint (ray
// cones, Akenine-Moller et al. 2019) instead of one texel of the full-resolution image: the same
// mean albedo with less noise, and lookups that stay in cache (full-resolution texel fetches can
// cost more than the ray traversal).
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <vector>

#include "io/context.h"
#include "io/scene.h"

namespace gibake {

struct MipLevel {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba8;  // same encoding as the texture (sRGB rgb, linear alpha)
};

// A footprint never spans more than this share of its triangle's own extent in uv (the square root
// of its uv area): past the triangle the texture holds other surfaces (an atlas's other islands, a
// trim sheet's other strips), and a wider filter would mix their colours into this one. Without
// the cap a wide cone reads a surface's albedo biased by its neighbours in the image.
inline constexpr float kMaxFootprintOfTriangle = 0.25f;

// Whether texture `texture`'s alpha is coverage: the base colour of a material whose alpha mode is
// MASK or BLEND (traced as a mask, io/scene.h). Its levels weigh colour by alpha.
bool texture_is_coverage(const Scene& scene, int texture);

class TextureLod {
 public:
  TextureLod() = default;
  // Builds level 1.. of every texture with pixels (2x2 box filter; sRGB channels averaged as
  // linear light and re-encoded, weighted by alpha where it is coverage) and each triangle's
  // sqrt(uv area / world area).
  // In `arena` when given (a caller's arena of --threads, shared with stages beside this one),
  // otherwise in one of ctx.threads.
  TextureLod(const Scene& scene, const Context& ctx, tbb::task_arena* arena = nullptr);

  // Levels of texture t beyond the full-resolution image (level 0 is Texture::rgba8 itself).
  const std::vector<MipLevel>& levels(int texture) const { return mips_[size_t(texture)]; }
  bool empty() const { return mips_.empty(); }
  // Mip level for a footprint `width` metres wide on triangle `tri` seen at |cos| `cos_theta`,
  // for a texture of w x h texels under a texture-transform scale (su, sv); 0 = full resolution.
  // The footprint is capped at kMaxFootprintOfTriangle of the triangle's uv extent.
  float level_of(uint32_t tri, float width, float cos_theta, int w, int h, float su, float sv) const;
  // Starts loading what level_of reads for triangle tri (a hint: no value depends on it).
  void prefetch(uint32_t tri) const {
#if defined(__GNUC__) || defined(__clang__)
    if (tri < extent_.size()) __builtin_prefetch(&extent_[tri]);
#else
    (void)tri;
#endif
  }
  // Triangle tri's sqrt(uv area / world area) (0 past the end), for the GPU's copy.
  float uv_per_metre(uint32_t tri) const { return tri < extent_.size() ? extent_[tri].uv_per_metre : 0.f; }
  // The widest footprint triangle tri reads, in uv units: kMaxFootprintOfTriangle x sqrt(its uv
  // area) (0 past the end), for the GPU's copy.
  float max_uv_width(uint32_t tri) const { return tri < extent_.size() ? extent_[tri].max_uv_width : 0.f; }

 private:
  std::vector<std::vector<MipLevel>> mips_;  // per texture
  // Per triangle, side by side so that a hit's lookup reads one place in memory.
  struct UvExtent {
    float uv_per_metre = 0.f;  // sqrt(uv area / world area)
    float max_uv_width = 0.f;  // kMaxFootprintOfTriangle x sqrt(uv area)
  };
  std::vector<UvExtent> extent_;
};

}  // namespace gibake
