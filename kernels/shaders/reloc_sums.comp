// Relocation statistics on the device: the twin of relocation_sums (bake/ddgi/relocate.cpp) over the
// records geometry_record would make of one probe's closest hits, so only 32 bytes a probe come
// back instead of every hit. One invocation per probe, its rays summed in ray order (the CPU's
// order: the result is deterministic and, with doubles, bit-identical to the CPU's sums). A hit is
// a front face when the ray comes from the side of cross(v1 - v0, v2 - v0) or the material is
// double sided; front hits nearer than the threshold add -dir * (threshold - depth), the
// subtraction in float and the product and sum in double, as the CPU does. A dispatch sums one
// window of each probe's rays (push.counts.zw, GPU_RAY_WINDOW at most) on top of the sums the window
// before stored, so no loop grows with the rays.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Tris { GpuRelocTri tris[]; };  // per Scene triangle
layout(std430, set = 0, binding = 1) readonly buffer Rays { GpuRay rays[]; };
layout(std430, set = 0, binding = 2) readonly buffer Hits { GpuHit hits[]; };
layout(std430, set = 0, binding = 3) buffer Sums { GpuRelocSums sums[]; };
layout(push_constant) uniform Push { RelocSumsPush push; };

uvec2 bits(double d) { return unpackDouble2x32(d); }

void main() {
  const uint p = GIBAKE_FLAT_INVOCATION;
  if (p >= push.counts.x) return;
  const uint n = push.counts.y, w0 = push.counts.z, w1 = min(n, w0 + push.counts.w);
  const float threshold = push.params.x;
  precise dvec3 delta = dvec3(0.0);
  bool close = false;
  float nearest = threshold;
  if (w0 > 0u) {  // the windows before
    const GpuRelocSums s = sums[p];
    delta = dvec3(packDouble2x32(s.delta_xy.xy), packDouble2x32(s.delta_xy.zw), packDouble2x32(s.delta_z_close.xy));
    nearest = uintBitsToFloat(s.delta_z_close.z);
    close = s.delta_z_close.w != 0u;
  }
  for (uint r = w0; r < w1; ++r) {
    const uint i = p * n + r;
    const vec4 h = hits[i].t_tri_uv;
    if (h.x < 0.0) continue;  // a miss
    const vec3 dir = rays[i].dir_tmax.xyz;
    const GpuRelocTri tri = tris[floatBitsToUint(h.y)];
    precise float facing = dir.x * tri.ng.x + dir.y * tri.ng.y + dir.z * tri.ng.z;  // kernels::dot's order
    if (!(facing < 0.0) && tri.ng.w == 0.0) continue;  // a back face
    const float depth = h.x;
    if (depth >= threshold) continue;
    close = true;
    nearest = min(nearest, depth);
    precise float gap = threshold - depth;
    precise dvec3 step = dvec3(dir) * double(gap);
    delta = delta - step;
  }
  sums[p].delta_xy = uvec4(bits(delta.x), bits(delta.y));
  sums[p].delta_z_close = uvec4(bits(delta.z), floatBitsToUint(nearest), close ? 1u : 0u);
}
