// Probe ray directions: spherical Fibonacci set rotated by a random rotation per (probe, pass),
// with a counter-based generator so every number depends only on (seed, probe, pass, ray).
#pragma once
#include <cstdint>

#include "kernels/vec.h"

namespace gibake::kernels {

// Stateless hash of the 4-tuple (splitmix64 finaliser chained over the words).
uint64_t rng_hash(uint64_t seed, uint64_t probe, uint64_t pass, uint64_t ray);
// Uniform float in [0,1) from a key and a stream index (different streams are independent).
float rng_uniform(uint64_t key, uint32_t stream);

// Point i of an n-point spherical Fibonacci set (unit vector).
float3 spherical_fibonacci(uint32_t i, uint32_t n);

// Row-major 3x3 rotation, uniformly distributed over SO(3) (Shoemake's quaternion method).
struct Rotation3 {
  float m[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  float3 apply(const float3& v) const {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
            m[6] * v.x + m[7] * v.y + m[8] * v.z};
  }
};
Rotation3 random_rotation(uint64_t seed, uint32_t probe, uint32_t pass);

// Fills n unit directions (xyz, stride 3) for (probe, pass).
void generate_probe_rays(uint64_t seed, uint32_t probe, uint32_t pass, uint32_t n, float* dirs);

// The unrotated n-point spherical Fibonacci set (xyz, stride 3), computed once per ray count.
void spherical_fibonacci_set(uint32_t n, float* out);
// generate_probe_rays with the unrotated set precomputed (bit-identical output, no sin/cos per ray).
void generate_probe_rays_from_set(const float* fibonacci_set, uint64_t seed, uint32_t probe, uint32_t pass,
                                  uint32_t n, float* dirs);

}  // namespace gibake::kernels
