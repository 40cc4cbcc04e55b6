// Probe rays of the path gather, made on the device: the twin of
// kernels::generate_probe_rays_from_set followed by make_path_rays (bake/vulkan/path.cpp). A probe's
// rotation (kernels::random_rotation) arrives in its record, computed on the CPU once per probe, so
// no device's sin/cos can change it; the unrotated Fibonacci set is uploaded once. Directions use
// the CPU's operations in the CPU's order (`precise`: no fused multiply-adds, no reassociation), so
// they differ from it only where a device's sqrt or division rounds differently; keys are 64-bit
// integer hashes, identical everywhere. One ray per invocation, written where path.comp reads it
// (or, in mode 1, the relocation pass's geometry ray where traverse.comp reads it).
#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "gpu_types.h"
#include "rng.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Fibonacci { vec4 fib[]; };  // xyz, w unused
layout(std430, set = 0, binding = 1) readonly buffer Probes { GpuRayGenProbe probes[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Rays { GpuPathRay rays[]; };
// Mode 1 (counts.w): the relocation pass's geometry rays, in traverse.comp's layout, no keys.
layout(std430, set = 0, binding = 2) writeonly buffer GeoRays { GpuRay geo_rays[]; };
// Per lane position of a probe's rays, the ray it takes (bake/vulkan/raygen.h lane_order).
layout(std430, set = 0, binding = 3) readonly buffer Order { uint order[]; };
layout(push_constant) uniform Push { RayGenPush push; };

void main() {
  const uint i = GIBAKE_FLAT_INVOCATION;
  if (i >= push.counts.x) return;
  const uint g = push.counts.z + i;  // the ray's index in the chunk: probe slot-major
  const uint slot = g / push.counts.y, lane = g - slot * push.counts.y;
  const uint r = push.counts.w == 1u ? lane : order[lane];  // the ray at this lane position
  const GpuRayGenProbe pr = probes[slot];
  const vec3 v = fib[r].xyz;
  // Rotation3::apply, then kernels::normalize (v * (1 / length), zero for a zero vector).
  precise vec3 d = vec3(pr.rot0.x * v.x + pr.rot0.y * v.y + pr.rot0.z * v.z,
                        pr.rot1.x * v.x + pr.rot1.y * v.y + pr.rot1.z * v.z,
                        pr.rot2.x * v.x + pr.rot2.y * v.y + pr.rot2.z * v.z);
  precise float l = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  precise float inv = 1.0 / l;
  precise vec3 dir = l > 0.0 ? vec3(d.x * inv, d.y * inv, d.z * inv) : vec3(0.0);
  if (push.counts.w == 1u) {
    geo_rays[i].org_tmin = vec4(pr.org.xyz, 0.0);
    geo_rays[i].dir_tmax = vec4(dir, uintBitsToFloat(0x7F800000u));  // tmin 0, tmax infinity: the CPU pass's
    return;
  }
  const uint64_t seed = uint64_t(push.seed.x) | (uint64_t(push.seed.y) << 32);
  const uint64_t key = rng_hash(seed, uint64_t(pr.key.x), uint64_t(pr.key.y), uint64_t(r));
  rays[i].org = vec4(pr.org.xyz, 0.0);
  rays[i].dir = vec4(dir, 0.0);
  // zw: the key of the probe's emitter-sample shift (kernels::probe_light_uniforms).
  const uint64_t shift = rng_hash(seed, uint64_t(pr.key.x), uint64_t(pr.key.y), uint64_t(0xFFFFFFFEu));
  rays[i].key = uvec4(uint(key), uint(key >> 32), uint(shift), uint(shift >> 32));
}
