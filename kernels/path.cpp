#include "kernels/path.h"

#include <cmath>

#include "kernels/ray_gen.h"

namespace gibake::kernels {

float3 sample_cosine_hemisphere(const float3& n, float u1, float u2) {
  // Malley's method: a uniform point on the unit disk lifted onto the hemisphere.
  const float r = std::sqrt(u1);
  const float phi = 2.f * kPi * u2;
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  const float z = std::sqrt(std::fmax(0.f, 1.f - u1));
  // Orthonormal basis about n without branches on the sign (Duff et al. 2017).
  const float s = std::copysign(1.f, n.z);
  const float a = -1.f / (s + n.z);
  const float b = n.x * n.y * a;
  const float3 t{1.f + s * n.x * n.x * a, s * b, -s * n.x};
  const float3 bt{b, s + n.y * n.y * a, -n.y};
  return normalize(t * x + bt * y + n * z);
}

void sample_triangle_barycentrics(float u1, float u2, float& u, float& v) {
  // Square-root warping (Osada et al.).
  const float su = std::sqrt(u1);
  u = su * (1.f - u2);
  v = su * u2;
}

void probe_light_uniforms(uint64_t shift_key, uint32_t r, uint32_t n, float u[3]) {
  uint32_t x[3] = {n > 0 ? uint32_t((uint64_t(r) << 32) / n) : 0u, r * 3242174889u, r * 2447445414u};
  for (uint32_t k = 0; k < 3; ++k) {
    // The shift: a uniform's 24 bits in the high bits, so the sum's top 24 bits are uniform again.
    x[k] += uint32_t(rng_uniform(shift_key, k) * 16777216.f) << 8;
    u[k] = float(x[k] >> 8) * (1.f / 16777216.f);
  }
}

}  // namespace gibake::kernels
