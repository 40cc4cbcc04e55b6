#include "kernels/sh.h"

namespace gibake::kernels {

void sh_add_sample(const float3& d, const float3& radiance, float weight, int order, float* sh) {
  float y[kMaxShCoefficients];
  sh_basis(d, order, y);
  const int n = sh_coefficient_count(order);
  for (int c = 0; c < n; ++c) {
    const float w = y[c] * weight;
    sh[c * 3 + 0] += radiance.x * w;
    sh[c * 3 + 1] += radiance.y * w;
    sh[c * 3 + 2] += radiance.z * w;
  }
}

static float band_of(int c) { return c == 0 ? 0.f : (c < 4 ? 1.f : 2.f); }

float3 sh_irradiance(const float* sh, int order, const float3& n) {
  static constexpr float kA[3] = {kPi, 2.f * kPi / 3.f, kPi / 4.f};
  float y[kMaxShCoefficients];
  sh_basis(n, order, y);
  float3 e{};
  const int count = sh_coefficient_count(order);
  for (int c = 0; c < count; ++c) {
    const float w = kA[static_cast<int>(band_of(c))] * y[c];
    e.x += sh[c * 3 + 0] * w;
    e.y += sh[c * 3 + 1] * w;
    e.z += sh[c * 3 + 2] * w;
  }
  return e;
}

float3 sh_radiance(const float* sh, int order, const float3& d) {
  float y[kMaxShCoefficients];
  sh_basis(d, order, y);
  float3 l{};
  const int count = sh_coefficient_count(order);
  for (int c = 0; c < count; ++c) {
    l.x += sh[c * 3 + 0] * y[c];
    l.y += sh[c * 3 + 1] * y[c];
    l.z += sh[c * 3 + 2] * y[c];
  }
  return l;
}

void sh_project_uniform_cap(const float3& axis, float cos_half_angle, int order, float* out) {
  const float c = cos_half_angle;
  const float two_pi = 2.f * kPi;
  // z_l = 2pi * integral_{c}^{1} Y_l0(mu) dmu.
  const float z[3] = {two_pi * 0.282095f * (1.f - c), two_pi * 0.488603f * 0.5f * (1.f - c * c),
                      two_pi * 0.315392f * (c - c * c * c)};
  // Rotation of a zonal function: f_lm = sqrt(4pi/(2l+1)) z_l Y_lm(axis).
  float y[kMaxShCoefficients];
  sh_basis(axis, order, y);
  const int count = sh_coefficient_count(order);
  for (int i = 0; i < count; ++i) {
    const int l = static_cast<int>(band_of(i));
    out[i] = std::sqrt(4.f * kPi / (2.f * l + 1.f)) * z[l] * y[i];
  }
}

}  // namespace gibake::kernels
