#include "bake/vulkan/device_scene.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "bake/scene/material.h"
#include "bake/vulkan/bvh_cache.h"

namespace gibake {
using gpu::GpuBvhNode;
using gpu::GpuTriangle;

namespace {

// The builder's temporary tree, allocated by Embree (freed with the RTCBVH).
struct BuildNode {
  bool leaf = false;
};
struct BuildInner : BuildNode {
  BuildNode* child[2] = {nullptr, nullptr};
  RTCBounds bounds[2];
};
struct BuildLeaf : BuildNode {
  uint32_t count = 0;
  uint32_t tris[GPU_MAX_LEAF];
};

struct BuildUser {
  const Scene* scene = nullptr;
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int, void*) {
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildInner), 16);
  return new (mem) BuildInner();
}

void set_children(void* node, void** children, unsigned int count, void*) {
  auto* n = static_cast<BuildInner*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i) n->child[i] = static_cast<BuildNode*>(children[i]);
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
  auto* n = static_cast<BuildInner*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i) n->bounds[i] = *bounds[i];
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf), 16);
  auto* leaf = new (mem) BuildLeaf();
  leaf->leaf = true;
  leaf->count = static_cast<uint32_t>(std::min<size_t>(count, GPU_MAX_LEAF));
  for (uint32_t i = 0; i < leaf->count; ++i) leaf->tris[i] = prims[i].primID;
  return leaf;
}

// Spatial split of a triangle reference: the bounds of its parts on either side of the plane,
// clipped to the reference's current bounds (what the SAH builder's split boxes need).
void split_primitive(const RTCBuildPrimitive* prim, unsigned int dim, float pos, RTCBounds* left, RTCBounds* right,
                     void* user) {
  const Scene& scene = *static_cast<const BuildUser*>(user)->scene;
  const uint32_t* idx = &scene.indices[size_t(prim->primID) * 3];
  float lo[2][3], hi[2][3];
  for (int s = 0; s < 2; ++s)
    for (int k = 0; k < 3; ++k) lo[s][k] = INFINITY, hi[s][k] = -INFINITY;
  auto add = [&](int side, const float* p) {
    for (int k = 0; k < 3; ++k) lo[side][k] = std::min(lo[side][k], p[k]), hi[side][k] = std::max(hi[side][k], p[k]);
  };
  for (int e = 0; e < 3; ++e) {
    const float* a = &scene.positions[size_t(idx[e]) * 3];
    const float* b = &scene.positions[size_t(idx[(e + 1) % 3]) * 3];
    if (a[dim] <= pos) add(0, a);
    if (a[dim] >= pos) add(1, a);
    if ((a[dim] < pos && b[dim] > pos) || (a[dim] > pos && b[dim] < pos)) {
      const float t = (pos - a[dim]) / (b[dim] - a[dim]);
      float c[3];
      for (int k = 0; k < 3; ++k) c[k] = a[k] + t * (b[k] - a[k]);
      c[dim] = pos;
      add(0, c);
      add(1, c);
    }
  }
  const float plo[3] = {prim->lower_x, prim->lower_y, prim->lower_z};
  const float phi[3] = {prim->upper_x, prim->upper_y, prim->upper_z};
  RTCBounds* out[2] = {left, right};
  for (int s = 0; s < 2; ++s) {
    float l[3], h[3];
    for (int k = 0; k < 3; ++k) {
      l[k] = std::max(lo[s][k], plo[k]);
      h[k] = std::min(hi[s][k], phi[k]);
    }
    if (s == 0) h[dim] = std::min(h[dim], pos);
    else l[dim] = std::max(l[dim], pos);
    *out[s] = RTCBounds{l[0], l[1], l[2], 0.f, h[0], h[1], h[2], 0.f};
  }
}

// Depth-first flattening: inner nodes in pre-order, each leaf's triangle references contiguous.
struct Flattener {
  CachedBvh& out;

  uint32_t leaf_ref(const BuildLeaf& leaf) {
    const uint32_t first = static_cast<uint32_t>(out.triangle_of_ref.size());
    out.triangle_of_ref.insert(out.triangle_of_ref.end(), leaf.tris, leaf.tris + leaf.count);
    return GPU_LEAF_BIT | ((leaf.count - 1) << GPU_LEAF_COUNT_SHIFT) | first;
  }

  uint32_t visit(const BuildNode* node, uint32_t depth) {
    out.depth = std::max(out.depth, depth);
    if (node->leaf) return leaf_ref(*static_cast<const BuildLeaf*>(node));
    const auto* in = static_cast<const BuildInner*>(node);
    const uint32_t index = static_cast<uint32_t>(out.nodes.size());
    out.nodes.emplace_back();
    const RTCBounds& b0 = in->bounds[0];
    const RTCBounds& b1 = in->bounds[1];
    GpuBvhNode n{};
    n.c0_xy = {b0.lower_x, b0.upper_x, b0.lower_y, b0.upper_y};
    n.c1_xy = {b1.lower_x, b1.upper_x, b1.lower_y, b1.upper_y};
    n.z = {b0.lower_z, b0.upper_z, b1.lower_z, b1.upper_z};
    n.children.x = visit(in->child[0], depth + 1);
    n.children.y = visit(in->child[1], depth + 1);
    out.nodes[index] = n;
    return index;
  }
};

// The leaf-order triangles the traversal reads: the three corners, the Scene triangle and the alpha slot.
void pack_triangles(const Scene& scene, const std::vector<uint32_t>& refs, const std::vector<uint32_t>& alpha_slot,
                    std::vector<GpuTriangle>& out) {
  out.resize(refs.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, refs.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const uint32_t t = refs[i];
      const uint32_t* idx = &scene.indices[size_t(t) * 3];
      const float* p0 = &scene.positions[size_t(idx[0]) * 3];
      const float* p1 = &scene.positions[size_t(idx[1]) * 3];
      const float* p2 = &scene.positions[size_t(idx[2]) * 3];
      GpuTriangle g;
      float tri_bits, slot_bits;
      const uint32_t slot = alpha_slot[t];
      std::memcpy(&tri_bits, &t, 4);
      std::memcpy(&slot_bits, &slot, 4);
      g.v0 = {p0[0], p0[1], p0[2], tri_bits};
      g.v1 = {p1[0], p1[1], p1[2], slot_bits};
      g.v2 = {p2[0], p2[1], p2[2], 0.f};
      out[i] = g;
    }
  });
}

gpu::GpuMaterial pack_material(const Material& m, float blend_cutoff, uint32_t texture) {
  gpu::GpuMaterial g{};
  g.base_color = {m.base_color[0], m.base_color[1], m.base_color[2], m.base_color[3]};
  const TextureRef& r = m.base_color_texture;
  g.xform = {r.offset[0], r.offset[1], r.scale[0], r.scale[1]};
  g.params = {r.rotation, alpha_cutoff_of(m, blend_cutoff), r.has_transform ? 1.f : 0.f, 0.f};
  g.tex = {texture, m.double_sided ? 1u : 0u, 0u, 0u};
  return g;
}

// Materials and the textures the alpha test reads (base colour of masked materials).
Status pack_materials(const Scene& scene, float blend_cutoff, GpuSceneData& out) {
  std::vector<uint32_t> gpu_texture(scene.textures.size(), GPU_NO_TEXTURE);
  out.materials.clear();
  for (size_t i = 0; i <= scene.materials.size(); ++i) {
    static const Material kDefault{};
    const Material& m = i < scene.materials.size() ? scene.materials[i] : kDefault;
    uint32_t tex = GPU_NO_TEXTURE;
    const int ti = m.base_color_texture.texture;
    const bool masked = alpha_cutoff_of(m, blend_cutoff) >= 0.f;
    if (masked && ti >= 0 && size_t(ti) < scene.textures.size()) {
      const Texture& t = scene.textures[size_t(ti)];
      if (t.width > 0 && t.height > 0 && t.rgba8.size() >= size_t(t.width) * t.height * 4) {
        if (gpu_texture[size_t(ti)] == GPU_NO_TEXTURE) {
          gpu_texture[size_t(ti)] = static_cast<uint32_t>(out.textures.size());
          const uint64_t first = out.texels.size();
          if (first + uint64_t(t.width) * t.height > 0xFFFFFFFFull)
            return Status::error(ExitCode::RuntimeFailure, scene.source_path, "gpu scene", "texel pool over 2^32 texels");
          out.textures.push_back({{static_cast<uint32_t>(first), uint32_t(t.width), uint32_t(t.height),
                                   uint32_t(t.wrap_s) | uint32_t(t.wrap_t) << 16}});
          out.texels.resize(first + size_t(t.width) * t.height);
          std::memcpy(&out.texels[first], t.rgba8.data(), size_t(t.width) * t.height * 4);
        }
        tex = gpu_texture[size_t(ti)];
      }
    }
    out.materials.push_back(pack_material(m, blend_cutoff, tex));
  }
  return Status::ok();
}

// Alpha records of masked triangles; slot[t] = 1 + record index (0: opaque).
std::vector<uint32_t> pack_alpha_triangles(const Scene& scene, float blend_cutoff, GpuSceneData& out) {
  const size_t n = scene.triangle_count();
  std::vector<uint32_t> slot(n, 0);
  const bool have_uv = scene.uvs.size() >= scene.vertex_count() * 2;
  const bool have_color = scene.colors.size() >= scene.vertex_count() * 4;
  const uint32_t default_material = static_cast<uint32_t>(scene.materials.size());
  for (size_t t = 0; t < n; ++t) {
    if (alpha_cutoff_of(triangle_material(scene, uint32_t(t)), blend_cutoff) < 0.f) continue;
    const uint32_t* idx = &scene.indices[t * 3];
    float uv[6] = {0, 0, 0, 0, 0, 0}, a[3] = {1.f, 1.f, 1.f};
    for (int k = 0; k < 3; ++k) {
      if (have_uv) uv[2 * k] = scene.uvs[size_t(idx[k]) * 2], uv[2 * k + 1] = scene.uvs[size_t(idx[k]) * 2 + 1];
      if (have_color) a[k] = scene.colors[size_t(idx[k]) * 4 + 3];
    }
    const int32_t m = t < scene.tri_material.size() ? scene.tri_material[t] : -1;
    const uint32_t mat = m < 0 || size_t(m) >= scene.materials.size() ? default_material : uint32_t(m);
    gpu::GpuAlphaTriangle at{};
    at.uv01 = {uv[0], uv[1], uv[2], uv[3]};
    at.uv2_a01 = {uv[4], uv[5], a[0], a[1]};
    uint32_t a2;
    std::memcpy(&a2, &a[2], 4);
    at.a2_mat = {a2, mat, 0u, 0u};
    out.alpha_triangles.push_back(at);
    slot[t] = static_cast<uint32_t>(out.alpha_triangles.size());
  }
  return slot;
}

// Runs `f` in the build's arena: the caller's, else one of ctx.threads, else the default one.
template <class F>
void in_build_arena(const GpuSceneOptions& options, const Context& ctx, F&& f) {
  if (options.arena) {
    options.arena->execute(f);
  } else if (ctx.threads > 0) {
    tbb::task_arena arena(static_cast<int>(ctx.threads));
    arena.execute(f);
  } else {
    f();
  }
}

// Embree's SAH build of every triangle with finite corners, flattened (root GPU_NO_ROOT: none).
Status build_tree(const Scene& scene, const GpuSceneOptions& options, const Context& ctx, CachedBvh& out) {
  const size_t n = scene.triangle_count();
  const size_t vcount = scene.vertex_count();
  // Build primitives: every triangle with valid indices, room for spatial-split references.
  std::vector<RTCBuildPrimitive> prims;
  prims.reserve(2 * n + 1);
  for (size_t t = 0; t < n; ++t) {
    const uint32_t* idx = &scene.indices[t * 3];
    if (idx[0] >= vcount || idx[1] >= vcount || idx[2] >= vcount)
      return Status::invalid(scene.source_path, "triangle " + std::to_string(t), "vertex index out of range");
    RTCBuildPrimitive p{INFINITY, INFINITY, INFINITY, 0u, -INFINITY, -INFINITY, -INFINITY, static_cast<unsigned>(t)};
    bool finite = true;
    for (int k = 0; k < 3; ++k) {
      const float* v = &scene.positions[size_t(idx[k]) * 3];
      finite = finite && std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
      p.lower_x = std::min(p.lower_x, v[0]), p.upper_x = std::max(p.upper_x, v[0]);
      p.lower_y = std::min(p.lower_y, v[1]), p.upper_y = std::max(p.upper_y, v[1]);
      p.lower_z = std::min(p.lower_z, v[2]), p.upper_z = std::max(p.upper_z, v[2]);
    }
    if (finite) prims.push_back(p);  // Embree skips non-finite triangles too
  }
  if (prims.empty()) return Status::ok();
  const size_t count = prims.size();
  prims.resize(prims.capacity());
  const bool own_device = options.embree_device == nullptr;
  RTCDevice device = own_device ? rtcNewDevice(nullptr) : static_cast<RTCDevice>(options.embree_device);
  if (!device) return Status::error(ExitCode::RuntimeFailure, scene.source_path, "embree", "rtcNewDevice failed");
  RTCBVH bvh = rtcNewBVH(device);
  BuildUser user{&scene};
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildQuality = options.spatial_splits ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = GPU_STACK - 4;  // the traversal stack holds at most one entry per level
  args.sahBlockSize = 1;
  args.minLeafSize = 1;
  args.maxLeafSize = std::clamp<uint32_t>(options.max_leaf, 1, GPU_MAX_LEAF);
  args.traversalCost = 1.f;
  args.intersectionCost = 1.f;
  args.bvh = bvh;
  args.primitives = prims.data();
  args.primitiveCount = count;
  args.primitiveArrayCapacity = prims.size();
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  args.splitPrimitive = split_primitive;
  args.userPtr = &user;
  void* root = nullptr;
  in_build_arena(options, ctx, [&] { root = rtcBuildBVH(&args); });
  Status st = Status::ok();
  if (!root) {
    st = Status::error(ExitCode::RuntimeFailure, scene.source_path, "embree",
                       "rtcBuildBVH failed (error " + std::to_string(int(rtcGetDeviceError(device))) + ")");
  } else {
    Flattener f{out};
    out.root = f.visit(static_cast<BuildNode*>(root), 0);
  }
  rtcReleaseBVH(bvh);
  if (own_device) rtcReleaseDevice(device);
  return st;
}

}  // namespace

Status build_gpu_scene(const Scene& scene, const GpuSceneOptions& options, const Context& ctx, GpuSceneData& out) {
  out = GpuSceneData{};
  const size_t n = scene.triangle_count();
  out.scene_triangles = n;
  if (n > GPU_LEAF_FIRST_MASK / 2)
    return Status::error(
        ExitCode::RuntimeFailure, scene.source_path, "gpu scene",
        std::to_string(n) + " triangles: the GPU BVH holds at most " + std::to_string(GPU_LEAF_FIRST_MASK / 2));
  GIBAKE_TRY(pack_materials(scene, options.blend_cutoff, out));
  const std::vector<uint32_t> alpha_slot = pack_alpha_triangles(scene, options.blend_cutoff, out);
  CachedBvh tree;
  bool cached = false;
  const bool use_cache = !options.cache_dir.empty();
  BvhCacheKey key;
  if (use_cache) {  // an entry exists only for geometry that built: its indices are in range
    key = bvh_cache_key(scene, BvhBuildParams{options.spatial_splits, options.max_leaf});
    std::string problem;
    GIBAKE_TRY(load_cached_bvh(options.cache_dir, key, n, tree, cached, problem));
    if (!problem.empty()) out.cache_note = "BVH cache entry rebuilt: " + problem;
  }
  if (!cached) {
    GIBAKE_TRY(build_tree(scene, options, ctx, tree));
    if (use_cache && tree.root != GPU_NO_ROOT) {
      const Status stored = store_cached_bvh(options.cache_dir, key, tree, options.cache_budget_bytes);
      if (!stored) out.cache_note = "BVH not cached: " + stored.message();
      out.stored_in_cache = bool(stored);
    }
  }
  out.from_cache = cached;
  out.root = tree.root;
  out.depth = tree.depth;
  out.nodes = std::move(tree.nodes);
  in_build_arena(options, ctx, [&] { pack_triangles(scene, tree.triangle_of_ref, alpha_slot, out.triangles); });
  return Status::ok();
}

}  // namespace gibake
