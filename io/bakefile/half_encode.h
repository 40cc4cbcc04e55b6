// The bake writer's hot loops: float payloads encoded as float16 and scanned for values beyond its
// range. On x86-64 CPUs with F16C they run 8 values a step (vcvtps2ph), elsewhere one at a time;
// both give exactly the bytes of loader::float_to_half on the clamped value (NaN: sign | 0x7E00),
// which tests/io/half_encode_test.cpp checks over every float.
#pragma once
#include <cstddef>
#include <cstdint>

namespace gibake {

// Whether a finite value has a magnitude above 65504 (the largest float16).
bool any_beyond_half(const float* values, size_t n);

// `n` values as float16 into `dst` (2n bytes, unaligned is fine); finite magnitudes above 65504 are
// clamped to +-65504 first. Returns how many were clamped.
size_t encode_half(const float* values, size_t n, uint8_t* dst);

// The one-at-a-time versions (the reference the fast ones are tested against).
bool any_beyond_half_scalar(const float* values, size_t n);
size_t encode_half_scalar(const float* values, size_t n, uint8_t* dst);

// Whether this CPU takes the F16C path.
bool half_encode_fast();

}  // namespace gibake
