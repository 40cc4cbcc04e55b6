// Every texture of a scene with its mip chain on the device, as the path kernel reads them
// (kernels/shaders/path.comp: shade_tex, levels, pool, srgb). It depends only on the scene and its
// mips, so the bake's set-up uploads it beside the BVH build (bake/run/bake_setup.cpp) instead of
// after relocation; the path tracer takes it from the session (or makes its own).
#pragma once
#include <cstdint>
#include <memory>

#include "bake/scene/texture_lod.h"
#include "io/scene.h"
#include "io/status.h"
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

// Packs (in the calling task arena) and uploads. Fails with the bytes needed when the device lacks them.
Status create_gpu_texture_pool(vk::Context& vk, const Scene& scene, const TextureLod& lod,
                               std::unique_ptr<GpuTexturePool>& out);

}  // namespace gibake
