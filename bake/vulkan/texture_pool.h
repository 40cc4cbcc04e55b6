// Every texture of a scene with its mip chain on the device, as the path kernel reads them
// (kernels/shaders/path.comp: shade_tex, levels, pool, srgb). It depends only on the scene and its
// mips, so the bake's set-up uploads it beside the BVH build (bake/run/bake_setup.cpp) instead of
// after relocation; the path tracer takes it from the session (or makes its own).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "bake/scene/texture_lod.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/shaders/gpu_types.h"
#include "kernels/vulkan/context.h"

namespace gibake {

struct GpuTexturePool {
  vk::Buffer textures;  // GpuShadeTexture per scene texture: first level, level count, wrap modes
  vk::Buffer levels;    // GpuTexLevel per level: first texel in the pool, width, height
  vk::Buffer pool;      // every level's texels, RGBA8 (~10^8 bytes on Sponza)
  vk::Buffer srgb;      // the 256-entry sRGB-to-linear table
  uint64_t pool_bytes = 0;
  uint64_t device_bytes = 0;
  const TextureLod* lod = nullptr;  // the mips it was made from (a tracer checks it is handed the same)
  double pack_seconds = 0.0, upload_seconds = 0.0;
};

// The pool packed on the host, before any device is needed (the bake's set-up packs it while the
// driver is still opening the device).
struct PackedTextures {
  std::vector<gpu::GpuShadeTexture> textures;
  std::vector<gpu::GpuTexLevel> levels;
  std::unique_ptr<uint32_t[]> pool;  // uninitialised beyond `texels`
  size_t texels = 0;
  std::vector<float> srgb;
  const TextureLod* lod = nullptr;
  double seconds = 0.0;
};

// Packs every texture and mip in the calling task arena.
void pack_gpu_textures(const Scene& scene, const TextureLod& lod, PackedTextures& out);
// Uploads a packed pool (its host memory freed after). Fails with the bytes needed when the device
// lacks them.
Status upload_gpu_texture_pool(vk::Context& vk, PackedTextures&& packed, std::unique_ptr<GpuTexturePool>& out);
// Both, one after the other.
Status create_gpu_texture_pool(vk::Context& vk, const Scene& scene, const TextureLod& lod,
                               std::unique_ptr<GpuTexturePool>& out);

}  // namespace gibake
