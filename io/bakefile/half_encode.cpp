#include "io/bakefile/half_encode.h"

#include <cstring>

#include "gibake/loader.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define GIBAKE_HAVE_F16C_PATH 1
#endif

namespace gibake {
namespace {

constexpr uint32_t kHalfMaxBits = 0x477FE000u;  // 65504.f
constexpr uint32_t kInfBits = 0x7F800000u;

inline bool beyond_half(uint32_t bits) {
  const uint32_t mag = bits & 0x7FFFFFFFu;
  return mag > kHalfMaxBits && mag < kInfBits;
}

#ifdef GIBAKE_HAVE_F16C_PATH
// |v| > 65504 and finite, per lane (ordered compares are false for NaN).
__attribute__((target("avx,f16c"))) inline __m256 beyond_mask(__m256 v, __m256 abs_mask) {
  const __m256 mag = _mm256_and_ps(v, abs_mask);
  return _mm256_and_ps(_mm256_cmp_ps(mag, _mm256_set1_ps(65504.f), _CMP_GT_OQ),
                       _mm256_cmp_ps(mag, _mm256_set1_ps(__builtin_inff()), _CMP_LT_OQ));
}

__attribute__((target("avx,f16c"))) bool any_beyond_f16c(const float* v, size_t n) {
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  size_t i = 0;
  for (; i + 32 <= n; i += 32) {  // four vectors a step, one test
    __m256 any = beyond_mask(_mm256_loadu_ps(v + i), abs_mask);
    any = _mm256_or_ps(any, beyond_mask(_mm256_loadu_ps(v + i + 8), abs_mask));
    any = _mm256_or_ps(any, beyond_mask(_mm256_loadu_ps(v + i + 16), abs_mask));
    any = _mm256_or_ps(any, beyond_mask(_mm256_loadu_ps(v + i + 24), abs_mask));
    if (_mm256_movemask_ps(any)) return true;
  }
  return any_beyond_half_scalar(v + i, n - i);
}

__attribute__((target("avx,f16c,popcnt"))) size_t encode_half_f16c(const float* v, size_t n, uint8_t* dst) {
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  const __m256 sign_mask = _mm256_castsi256_ps(_mm256_set1_epi32(int(0x80000000u)));
  const __m256 half_max = _mm256_set1_ps(65504.f);
  const __m256 quiet_nan = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FC00000));  // -> 0x7E00
  size_t clamped = 0, i = 0;
  for (; i + 8 <= n; i += 8) {
    __m256 x = _mm256_loadu_ps(v + i);
    const __m256 sign = _mm256_and_ps(x, sign_mask);
    const __m256 beyond = beyond_mask(x, abs_mask);
    const __m256 nan = _mm256_cmp_ps(x, x, _CMP_UNORD_Q);
    clamped += size_t(__builtin_popcount(unsigned(_mm256_movemask_ps(beyond))));
    // Selects by and/andnot/or: GCC lowers blendv on a comparison's mask to per-lane branches.
    x = _mm256_or_ps(_mm256_andnot_ps(beyond, x), _mm256_and_ps(beyond, _mm256_or_ps(sign, half_max)));
    // The loader's NaN is quiet with no payload: drop the payload, keep the sign.
    x = _mm256_or_ps(_mm256_andnot_ps(nan, x), _mm256_and_ps(nan, _mm256_or_ps(sign, quiet_nan)));
    const __m128i h = _mm256_cvtps_ph(x, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + 2 * i), h);
  }
  return clamped + encode_half_scalar(v + i, n - i, dst + 2 * i);
}

bool detect_f16c() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx") && __builtin_cpu_supports("f16c") && __builtin_cpu_supports("popcnt");
}
#endif

}  // namespace

bool any_beyond_half_scalar(const float* v, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    uint32_t bits;
    std::memcpy(&bits, v + i, 4);
    if (beyond_half(bits)) return true;
  }
  return false;
}

size_t encode_half_scalar(const float* v, size_t n, uint8_t* dst) {
  size_t clamped = 0;
  for (size_t i = 0; i < n; ++i) {
    float x = v[i];
    uint32_t bits;
    std::memcpy(&bits, &x, 4);
    if (beyond_half(bits)) {
      x = (bits >> 31) ? -65504.f : 65504.f;
      ++clamped;
    }
    const uint16_t h = loader::float_to_half(x);
    std::memcpy(dst + 2 * i, &h, 2);
  }
  return clamped;
}

bool half_encode_fast() {
#ifdef GIBAKE_HAVE_F16C_PATH
  static const bool fast = detect_f16c();
  return fast;
#else
  return false;
#endif
}

bool any_beyond_half(const float* v, size_t n) {
#ifdef GIBAKE_HAVE_F16C_PATH
  if (half_encode_fast()) return any_beyond_f16c(v, n);
#endif
  return any_beyond_half_scalar(v, n);
}

size_t encode_half(const float* v, size_t n, uint8_t* dst) {
#ifdef GIBAKE_HAVE_F16C_PATH
  if (half_encode_fast()) return encode_half_f16c(v, n, dst);
#endif
  return encode_half_scalar(v, n, dst);
}

}  // namespace gibake
