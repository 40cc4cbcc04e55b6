// One LPV propagation step and its accumulation: the twin of kernels::lpv_propagate +
// lpv_accumulate. Each destination cell gathers from its 6 neighbours, each sending through the
// 5 faces of the destination that do not touch it; occlusion from the geometry volume on the
// shared face's 4 corners (from the second step on).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Src { GpuLpvCell src[]; };
layout(std430, set = 0, binding = 1) readonly buffer Scale { vec4 scale[]; };
layout(std430, set = 0, binding = 2) readonly buffer Faces { GpuLpvFace faces[]; };
layout(std430, set = 0, binding = 3) readonly buffer Geometry { vec4 geometry[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Dst { GpuLpvCell dst[]; };
layout(std430, set = 0, binding = 5) buffer Acc { GpuLpvCell acc[]; };
layout(push_constant) uniform Push { LpvPush push; };

uint corner_index(ivec3 c) {
  return uint(c.x) + (push.dims.x + 1u) * (uint(c.y) + (push.dims.y + 1u) * uint(c.z));
}

void main() {
  uint i = GIBAKE_FLAT_INVOCATION;
  ivec3 dims = ivec3(push.dims.xyz);
  if (i >= uint(dims.x * dims.y * dims.z)) return;
  ivec3 cell = ivec3(int(i % uint(dims.x)), int((i / uint(dims.x)) % uint(dims.y)), int(i / uint(dims.x * dims.y)));
  vec4 o[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
  for (int k = 0; k < 6; ++k) {
    int axis = k / 2, sign = (k % 2 == 0) ? 1 : -1;
    ivec3 s = cell;
    s[axis] -= sign;
    if (any(lessThan(s, ivec3(0))) || any(greaterThanEqual(s, dims))) continue;
    uint si = uint(s.x) + uint(dims.x) * (uint(s.y) + uint(dims.y) * uint(s.z));
    vec4 sc = scale[si];
    if (sc.x == 0.0 && sc.y == 0.0 && sc.z == 0.0) continue;
    GpuLpvCell in_cell = src[si];
    vec4 sh[3] = vec4[3](in_cell.r, in_cell.g, in_cell.b);
    vec4 blocking = vec4(0.0);
    bool occlude = push.dims.w != 0u;
    if (occlude) {
      int a = axis, b = (axis + 1) % 3, c = (axis + 2) % 3;
      ivec3 corner;
      corner[a] = cell[a] + (sign < 0 ? 1 : 0);
      for (int u = 0; u < 2; ++u)
        for (int v = 0; v < 2; ++v) {
          corner[b] = cell[b] + u;
          corner[c] = cell[c] + v;
          blocking += geometry[corner_index(corner)];
        }
    }
    for (int f = 0; f < 5; ++f) {
      GpuLpvFace face = faces[k * 5 + f];
      float t = occlude ? 1.0 - clamp(0.25 * dot(blocking, face.basis), 0.0, 1.0) : 1.0;
      if (t <= 0.0) continue;
      float w = face.params.x * t;
      int li = int(face.params.w);
      for (int ch = 0; ch < 3; ++ch) {
        float flux = w * max(0.0, dot(sh[ch], face.basis)) * sc[ch];
        o[ch].x += flux * face.params.y;
        o[ch][li] += flux * face.params.z;
      }
    }
  }
  dst[i] = GpuLpvCell(o[0], o[1], o[2]);
  GpuLpvCell a = acc[i];
  acc[i] = GpuLpvCell(a.r + o[0], a.g + o[1], a.b + o[2]);
}
