#include "kernels/path.h"

#include <cmath>

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

}  // namespace gibake::kernels
