// A Scene packed for the GPU kernels: a binary BVH built on the CPU with Embree's rtcBuildBVH
// (SAH), triangles in leaf order, and what the alpha test reads (materials, textures, the uvs and
// vertex alphas of masked triangles). Plain data in the layouts of kernels/shaders/gpu_types.h.
#pragma once
#include <tbb/task_arena.h>

#include <cstdint>
#include <string>
#include <vector>

#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/shaders/gpu_types.h"

namespace gibake {

struct GpuSceneData {
  uint32_t root = GPU_NO_ROOT;               // child reference of the root (a leaf for tiny scenes)
  std::vector<gpu::GpuBvhNode> nodes;
  std::vector<gpu::GpuTriangle> triangles;   // leaf order; v0.w = Scene triangle
  std::vector<gpu::GpuAlphaTriangle> alpha_triangles;
  std::vector<gpu::GpuMaterial> materials;   // Scene materials, then the default one last
  std::vector<gpu::GpuTexture> textures;
  std::vector<uint32_t> texels;              // RGBA8 packed little-endian (r in the low byte)
  size_t scene_triangles = 0;
  uint32_t depth = 0;                        // deepest leaf (the traversal stack needs <= this)
  bool from_cache = false;                   // the tree came from GpuSceneOptions::cache_dir
  bool stored_in_cache = false;              // the tree was built and stored there
  std::string cache_note;                    // why an entry was rebuilt or not stored; empty: neither
  // The BVH alone (nodes + triangles) per Scene triangle: the figure docs/ARCHITECTURE.md quotes.
  double bvh_bytes_per_triangle() const {
    if (scene_triangles == 0) return 0.0;
    return double(nodes.size() * sizeof(gpu::GpuBvhNode) + triangles.size() * sizeof(gpu::GpuTriangle)) /
           double(scene_triangles);
  }
  // Everything the tracer uploads (inline: the standalone GPU bench links no Embree).
  uint64_t bytes() const {
    return nodes.size() * sizeof(gpu::GpuBvhNode) + triangles.size() * sizeof(gpu::GpuTriangle) +
           alpha_triangles.size() * sizeof(gpu::GpuAlphaTriangle) + materials.size() * sizeof(gpu::GpuMaterial) +
           textures.size() * sizeof(gpu::GpuTexture) + texels.size() * 4;
  }
};

struct GpuSceneOptions {
  float blend_cutoff = kDefaultBlendCutoff;  // as PrepareOptions: BLEND traced as MASK with this cutoff
  uint32_t max_leaf = 4;      // triangles per leaf (1..GPU_MAX_LEAF)
  bool spatial_splits = true; // Embree's high-quality SAH builder (splits triangle references)
  // An RTCDevice the caller created outside any TBB arena (creating one inside an arena would set
  // Embree's process-wide thread cap to that arena's size); null: the build makes its own.
  void* embree_device = nullptr;
  // The arena the build runs in (a caller's arena shared with other tasks); null: one of ctx.threads.
  tbb::task_arena* arena = nullptr;
  // A folder of built trees (bake/vulkan/bvh_cache.h): the tree is loaded from it when the same
  // geometry was built with the same options before, else built and stored. Empty: always built.
  std::string cache_dir;
  uint64_t cache_budget_bytes = uint64_t(1) << 30;  // the folder's entries beyond it: oldest removed
};

// Builds the BVH (Embree's SAH builder, binary, depth < GPU_STACK), or loads it from the cache, and
// packs the scene. Fails with RuntimeFailure for scenes beyond the leaf encoding (2^27 triangles).
// A cache that cannot be read or written only costs the build (cache_note says why).
Status build_gpu_scene(const Scene& scene, const GpuSceneOptions& options, const Context& ctx, GpuSceneData& out);

}  // namespace gibake
