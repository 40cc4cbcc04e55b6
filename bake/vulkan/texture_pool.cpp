#include "bake/vulkan/texture_pool.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "io/timer.h"
#include "kernels/shaders/gpu_types.h"

namespace gibake {
namespace {

// The pool is ~10^8 bytes on a textured scene: levels are laid out first, then copied in parallel
// into memory that is never zero-filled (a serial fill and copy of that size is slow).
struct PendingLevel {
  const uint8_t* rgba;
  size_t first, texels;
};

void add_level(PackedTextures& pk, int w, int h, const uint8_t* rgba, std::vector<PendingLevel>& pending) {
  pk.levels.push_back({{uint32_t(pk.texels), uint32_t(w), uint32_t(h), 0u}});
  pending.push_back({rgba, pk.texels, size_t(w) * size_t(h)});
  pk.texels += size_t(w) * size_t(h);
}

void pack(const Scene& scene, const TextureLod& lod, PackedTextures& pk) {
  std::vector<PendingLevel> pending;
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    const Texture& tx = scene.textures[t];
    gpu::GpuShadeTexture g{{uint32_t(pk.levels.size()), 0u, uint32_t(tx.wrap_s) | uint32_t(tx.wrap_t) << 16, 0u}};
    if (tx.width > 0 && tx.height > 0 && tx.rgba8.size() >= size_t(tx.width) * tx.height * 4) {
      add_level(pk, tx.width, tx.height, tx.rgba8.data(), pending);
      g.info.y = 1;
      if (!lod.empty())
        for (const MipLevel& m : lod.levels(int(t))) {
          add_level(pk, m.width, m.height, m.rgba8.data(), pending);
          ++g.info.y;
        }
    }
    pk.textures.push_back(g);
  }
  pk.pool.reset(new uint32_t[std::max<size_t>(pk.texels, 1)]);
  tbb::parallel_for(size_t(0), pending.size(), [&](size_t i) {
    std::memcpy(pk.pool.get() + pending[i].first, pending[i].rgba, pending[i].texels * 4);
  });
  for (int i = 0; i < 256; ++i) {
    const float c = i / 255.f;
    pk.srgb.push_back(c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f));
  }
}

}  // namespace

void pack_gpu_textures(const Scene& scene, const TextureLod& lod, PackedTextures& out) {
  const Stopwatch packing;
  out = PackedTextures{};
  pack(scene, lod, out);
  out.lod = &lod;
  out.seconds = packing.seconds();
}

Status create_gpu_texture_pool(vk::Context& vk, const Scene& scene, const TextureLod& lod,
                               std::unique_ptr<GpuTexturePool>& out) {
  PackedTextures pk;
  pack_gpu_textures(scene, lod, pk);
  return upload_gpu_texture_pool(vk, std::move(pk), out);
}

Status upload_gpu_texture_pool(vk::Context& vk, PackedTextures&& packed, std::unique_ptr<GpuTexturePool>& out) {
  const PackedTextures pk = std::move(packed);  // freed on return
  auto p = std::make_unique<GpuTexturePool>();
  p->lod = pk.lod;
  p->pool_bytes = uint64_t(pk.texels) * 4;
  p->pack_seconds = pk.seconds;
  GIBAKE_TRY(vk.check_device_memory(p->pool_bytes, 0, "the scene's textures with their mips",
                                     "smaller textures lower it; --backend cpu bakes without the device"));
  const Stopwatch uploading;
  uint64_t& total = p->device_bytes;
  GIBAKE_TRY(vk.create_filled_buffer(pk.textures, p->textures, "textures", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.levels, p->levels, "texture levels", total));
  GIBAKE_TRY(
      vk.create_filled_buffer(pk.pool.get(), pk.texels, p->pool, "texel pool (every texture and its mips)", total));
  GIBAKE_TRY(vk.create_filled_buffer(pk.srgb, p->srgb, "sRGB table", total));
  p->upload_seconds = uploading.seconds();
  out = std::move(p);
  return Status::ok();
}

}  // namespace gibake
