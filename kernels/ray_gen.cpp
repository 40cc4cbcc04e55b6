#include "kernels/ray_gen.h"

#include <cmath>

namespace gibake::kernels {

static uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

uint64_t rng_hash(uint64_t seed, uint64_t probe, uint64_t pass, uint64_t ray) {
  uint64_t h = splitmix64(seed);
  h = splitmix64(h ^ probe);
  h = splitmix64(h ^ pass);
  h = splitmix64(h ^ ray);
  return h;
}

float rng_uniform(uint64_t key, uint32_t stream) {
  const uint64_t h = splitmix64(key ^ (0xD1B54A32D192ED03ull * (stream + 1ull)));
  return static_cast<float>(h >> 40) * (1.f / 16777216.f);  // 24 bits -> [0,1)
}

float3 spherical_fibonacci(uint32_t i, uint32_t n) {
  const double golden = 0.6180339887498949;  // PHI - 1
  double frac = static_cast<double>(i) * golden;
  frac -= std::floor(frac);
  const float phi = static_cast<float>(2.0 * 3.14159265358979323846 * frac);
  const float cos_theta = 1.f - (2.f * static_cast<float>(i) + 1.f) / static_cast<float>(n);
  const float sin_theta = std::sqrt(clampf(1.f - cos_theta * cos_theta, 0.f, 1.f));
  return {std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta};
}

Rotation3 random_rotation(uint64_t seed, uint32_t probe, uint32_t pass) {
  const uint64_t key = rng_hash(seed, probe, pass, 0xFFFFFFFFull);
  const float u1 = rng_uniform(key, 0), u2 = rng_uniform(key, 1), u3 = rng_uniform(key, 2);
  const float a = std::sqrt(1.f - u1), b = std::sqrt(u1);
  const float x = a * std::sin(2.f * kPi * u2), y = a * std::cos(2.f * kPi * u2);
  const float z = b * std::sin(2.f * kPi * u3), w = b * std::cos(2.f * kPi * u3);
  Rotation3 r;
  r.m[0] = 1 - 2 * (y * y + z * z); r.m[1] = 2 * (x * y - z * w);     r.m[2] = 2 * (x * z + y * w);
  r.m[3] = 2 * (x * y + z * w);     r.m[4] = 1 - 2 * (x * x + z * z); r.m[5] = 2 * (y * z - x * w);
  r.m[6] = 2 * (x * z - y * w);     r.m[7] = 2 * (y * z + x * w);     r.m[8] = 1 - 2 * (x * x + y * y);
  return r;
}

void generate_probe_rays(uint64_t seed, uint32_t probe, uint32_t pass, uint32_t n, float* dirs) {
  const Rotation3 rot = random_rotation(seed, probe, pass);
  for (uint32_t i = 0; i < n; ++i) store3(dirs + 3 * i, normalize(rot.apply(spherical_fibonacci(i, n))));
}

void spherical_fibonacci_set(uint32_t n, float* out) {
  for (uint32_t i = 0; i < n; ++i) store3(out + 3 * i, spherical_fibonacci(i, n));
}

void generate_probe_rays_from_set(const float* fib, uint64_t seed, uint32_t probe, uint32_t pass, uint32_t n,
                                  float* dirs) {
  const Rotation3 rot = random_rotation(seed, probe, pass);
  for (uint32_t i = 0; i < n; ++i) store3(dirs + 3 * i, normalize(rot.apply(load3(fib + 3 * i))));
}

}  // namespace gibake::kernels
