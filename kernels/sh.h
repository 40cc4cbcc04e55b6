// Real orthonormal spherical harmonics up to band 2, ordered as DESIGN.md:
// Y00; Y1-1 (y), Y10 (z), Y11 (x); Y2-2 (xy), Y2-1 (yz), Y20 (3z^2-1), Y21 (xz), Y22 (x^2-y^2).
// Coefficients are stored RGB-interleaved: sh[c*3 + channel], c < (order+1)^2.
#pragma once
#include "kernels/vec.h"

namespace gibake::kernels {

constexpr int kMaxShCoefficients = 9;

inline int sh_coefficient_count(int order) { return (order + 1) * (order + 1); }

// Basis values for a unit direction; writes sh_coefficient_count(order) values.
inline void sh_basis(const float3& d, int order, float* y);

// Adds weight * radiance * Y(d) into sh (RGB-interleaved).
void sh_add_sample(const float3& d, const float3& radiance, float weight, int order, float* sh);

// Irradiance for surface normal n from incident-radiance SH: E(n) = sum_l A_l sum_m L_lm Y_lm(n),
// A0 = pi, A1 = 2pi/3, A2 = pi/4. Result in lux when sh is in cd/m^2.
float3 sh_irradiance(const float* sh, int order, const float3& n);

// Radiance reconstructed from the (band-limited) SH in direction d.
float3 sh_radiance(const float* sh, int order, const float3& d);

// Zonal-harmonic coefficients z_l (l = 0..2) of a uniform cap of radiance 1 and half-angle theta
// around +axis, and their rotation to `axis`: out (RGB-less) has sh_coefficient_count(order) values.
void sh_project_uniform_cap(const float3& axis, float cos_half_angle, int order, float* out);

inline void sh_basis(const float3& d, int order, float* y) {
  y[0] = 0.282095f;
  if (order < 1) return;
  y[1] = 0.488603f * d.y;
  y[2] = 0.488603f * d.z;
  y[3] = 0.488603f * d.x;
  if (order < 2) return;
  y[4] = 1.092548f * d.x * d.y;
  y[5] = 1.092548f * d.y * d.z;
  y[6] = 0.315392f * (3.f * d.z * d.z - 1.f);
  y[7] = 1.092548f * d.x * d.z;
  y[8] = 0.546274f * (d.x * d.x - d.y * d.y);
}

}  // namespace gibake::kernels
