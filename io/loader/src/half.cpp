// IEEE 754 binary16 <-> binary32, round to nearest even.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "gibake/loader.hpp"

namespace gibake::loader {

float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t(h & 0x8000u) << 16;
  uint32_t exponent = (h >> 10) & 0x1Fu;
  uint32_t mantissa = h & 0x3FFu;
  uint32_t bits;
  if (exponent == 0x1F) {
    bits = sign | 0x7F800000u | (mantissa << 13);  // inf / NaN
  } else if (exponent != 0) {
    bits = sign | ((exponent + 112) << 23) | (mantissa << 13);
  } else if (mantissa == 0) {
    bits = sign;  // signed zero
  } else {
    // Subnormal: normalise.
    exponent = 113;
    while ((mantissa & 0x400u) == 0) {
      mantissa <<= 1;
      --exponent;
    }
    bits = sign | (exponent << 23) | ((mantissa & 0x3FFu) << 13);
  }
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

uint16_t float_to_half(float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  const uint16_t sign = uint16_t((bits >> 16) & 0x8000u);
  const uint32_t abs = bits & 0x7FFFFFFFu;
  if (abs >= 0x7F800000u)  // inf or NaN (keep NaN quiet and non-zero)
    return uint16_t(sign | 0x7C00u | (abs > 0x7F800000u ? 0x200u : 0u));
  if (abs >= 0x477FF000u) return uint16_t(sign | 0x7C00u);  // rounds above 65504: inf
  if (abs < 0x38800000u) {
    // Subnormal half (or zero): value = m * 2^-24.
    if (abs < 0x33000000u) return sign;  // below half of the smallest subnormal
    const uint32_t exponent = abs >> 23;
    const uint32_t mantissa = (abs & 0x7FFFFFu) | 0x800000u;
    const uint32_t shift = 126 - exponent;  // 14..24
    uint32_t m = mantissa >> shift;
    const uint32_t rem = mantissa & ((1u << shift) - 1);
    const uint32_t halfway = 1u << (shift - 1);
    if (rem > halfway || (rem == halfway && (m & 1u))) ++m;
    return uint16_t(sign | m);
  }
  uint32_t h = ((abs >> 13) - (112u << 10));  // rebias exponent, keep top 10 mantissa bits
  const uint32_t rem = abs & 0x1FFFu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) ++h;  // may carry into the exponent
  return uint16_t(sign | h);
}

// Shared exponent: 9-bit mantissas, exponent bias 15, value = m * 2^(e - 15 - 9).
std::array<float, 3> rgb9e5_to_float(uint32_t packed) {
  const int exponent = int(packed >> 27) - 24;
  return {std::ldexp(float(packed & 0x1FFu), exponent), std::ldexp(float((packed >> 9) & 0x1FFu), exponent),
          std::ldexp(float((packed >> 18) & 0x1FFu), exponent)};
}

uint32_t float_to_rgb9e5(float r, float g, float b) {
  const auto clamp = [](float v) { return v > 0.f ? std::min(v, kRgb9e5Max) : 0.f; };  // also NaN -> 0
  const float c[3] = {clamp(r), clamp(g), clamp(b)};
  const float largest = std::max({c[0], c[1], c[2]});
  // The shared exponent: floor(log2(largest)) + 1 + bias, at least 0 (frexp gives largest = f 2^e,
  // f in [0.5, 1), so floor(log2) = e - 1).
  int e = 0;
  if (largest > 0.f) std::frexp(largest, &e);
  int shared = largest > 0.f ? std::max(-16, e - 1) + 16 : 0;
  // Rounding the largest mantissa up to 512 moves to the next exponent.
  if (std::floor(std::ldexp(largest, 24 - shared) + 0.5f) >= 512.f) ++shared;
  uint32_t packed = uint32_t(shared) << 27;
  for (int k = 0; k < 3; ++k)
    packed |= std::min(511u, uint32_t(std::floor(std::ldexp(c[k], 24 - shared) + 0.5f))) << (9 * k);
  return packed;
}

}  // namespace gibake::loader
