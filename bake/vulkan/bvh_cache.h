// The GPU BVH of a scene kept on disk for the next bake of the same geometry. A spatial-split build
// traces faster on the GPU than a plain SAH build but costs the host several times as long
// (docs/BENCHMARKS.md has the figures); a repeated bake (another light, more probes, other rays)
// loads it instead.
//
// An entry holds the tree alone: the nodes, the root, the depth and, per triangle reference, its
// Scene triangle. The triangles' corners and alpha slots are packed again from the scene, so an
// entry depends only on the geometry the builder saw. Its key is an XXH3-128 of the positions and
// indices, the build options, the cache format, the gibake version and Embree's version: any of
// them changing gives another entry, never a stale one (a change to the builder, bake/vulkan/
// device_scene.cpp, or to the entry's layout must bump kFormat in bvh_cache.cpp). A loaded entry is checked (magic,
// key, sizes, XXH3-64 of the payload, every child and triangle reference in range) before its tree is used; one that
// fails is rebuilt and replaced. Entries are written to a temporary and renamed (AtomicFile without its fsync: a torn
// entry fails its checks), and the oldest are removed once the folder holds more than its budget. Loaded or built, the
// tree is the same bytes: the build is deterministic whatever the thread count (tests/vulkan/bvh_cache_test.cpp), so
// the cache never changes a bake.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/scene.h"
#include "io/status.h"
#include "kernels/shaders/gpu_types.h"

namespace gibake {

struct BvhCacheKey {
  uint64_t low = 0, high = 0;
  std::string file_name() const;  // "bvh-<32 hex digits>.gbvh"
};

// What the builder's result depends on besides the scene's geometry.
struct BvhBuildParams {
  bool spatial_splits = true;
  uint32_t max_leaf = 4;
};

BvhCacheKey bvh_cache_key(const Scene& scene, const BvhBuildParams& params);

struct CachedBvh {
  uint32_t root = GPU_NO_ROOT;
  uint32_t depth = 0;
  std::vector<gpu::GpuBvhNode> nodes;
  std::vector<uint32_t> triangle_of_ref;  // per reference (leaf order): its Scene triangle
};

// Reads the entry for `key` from `dir`. `found` false (and ok) when there is none; an entry that
// fails a check is reported in `problem` (found stays false) so that the caller can say why it
// rebuilds. `scene_triangles` bounds the triangle references.
Status load_cached_bvh(const std::string& dir, const BvhCacheKey& key, size_t scene_triangles, CachedBvh& out,
                       bool& found, std::string& problem);

// Writes the entry (creating `dir` when missing), then removes the least recently used entries
// while the folder's entries exceed `budget_bytes`.
Status store_cached_bvh(const std::string& dir, const BvhCacheKey& key, const CachedBvh& bvh, uint64_t budget_bytes);

}  // namespace gibake
