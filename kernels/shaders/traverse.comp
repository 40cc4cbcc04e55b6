// Ray traversal kernel: one ray per invocation, closest hit (mode 0) or any hit (mode 1).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Nodes { GpuBvhNode nodes[]; };
layout(std430, set = 0, binding = 1) readonly buffer Tris { GpuTriangle tris[]; };
layout(std430, set = 0, binding = 2) readonly buffer AlphaTris { GpuAlphaTriangle alpha_tris[]; };
layout(std430, set = 0, binding = 3) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, set = 0, binding = 4) readonly buffer Textures { GpuTexture textures[]; };
layout(std430, set = 0, binding = 5) readonly buffer Texels { uint texels[]; };
layout(std430, set = 0, binding = 6) readonly buffer Rays { GpuRay rays[]; };
// Mode 0: GpuHit per ray. Mode 1: one uint per ray in hits[i].t_tri_uv.x's place (1 = occluded).
layout(std430, set = 0, binding = 7) writeonly buffer Hits { GpuHit hits[]; };
layout(std430, set = 0, binding = 7) writeonly buffer Occluded { uint occluded[]; };
layout(push_constant) uniform Push { TraversePush push; };

#include "traverse.glsl"

void main() {
  uint i = GIBAKE_FLAT_INVOCATION;
  if (i >= push.params.x) return;
  GpuRay ray = rays[i];
  bool any_hit = push.params.y == 1u;
  float t, u, v;
  uint slot = traverse(push.params.z, ray.org_tmin.xyz, ray.dir_tmax.xyz, ray.org_tmin.w, ray.dir_tmax.w, any_hit,
                       t, u, v);
  if (any_hit) {
    occluded[i] = slot != GPU_NO_ROOT ? 1u : 0u;
  } else if (slot == GPU_NO_ROOT) {
    hits[i].t_tri_uv = vec4(-1.0, uintBitsToFloat(0u), 0.0, 0.0);
  } else {
    hits[i].t_tri_uv = vec4(t, tris[slot].v0.w, u, v);
  }
}
