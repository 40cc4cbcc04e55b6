// LPV flux normalisation per source cell and channel: the twin of kernels::lpv_flux_scale
// (scale = flux / sum over the 30 faces of solid angle x max(0, I(w))).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "gpu_types.h"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Src { GpuLpvCell src[]; };
layout(std430, set = 0, binding = 1) readonly buffer Faces { GpuLpvFace faces[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Scale { vec4 scale[]; };
layout(push_constant) uniform Push { LpvPush push; };

const float kSqrt4Pi = 3.5449077;

float channel_scale(vec4 sh) {
  float flux = kSqrt4Pi * sh.x;
  float sent = 0.0;
  if (flux > 0.0)
    for (int i = 0; i < 30; ++i) sent += faces[i].params.x * max(0.0, dot(sh, faces[i].basis));
  return (flux > 0.0 && sent > 0.0) ? flux / sent : 0.0;
}

void main() {
  uint i = GIBAKE_FLAT_INVOCATION;
  if (i >= push.dims.x * push.dims.y * push.dims.z) return;
  GpuLpvCell c = src[i];
  scale[i] = vec4(channel_scale(c.r), channel_scale(c.g), channel_scale(c.b), 0.0);
}
