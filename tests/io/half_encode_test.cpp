// The writer's fast float16 paths (io/bakefile/half_encode.h) against the one-at-a-time reference
// (loader::float_to_half on the clamped value), over every non-negative float bit pattern and every
// eighth block of the negative ones (the sign is one bit on both paths), in blocks of odd lengths
// so the vector loops' tails run too. The reference is itself checked against
// hand-worked values.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstring>
#include <vector>

#include "io/bakefile/half_encode.h"

namespace gibake {
namespace {

float from_bits(uint32_t b) {
  float f;
  std::memcpy(&f, &b, 4);
  return f;
}

uint16_t half_of(float f) {
  uint8_t out[2];
  encode_half_scalar(&f, 1, out);
  uint16_t h;
  std::memcpy(&h, out, 2);
  return h;
}

TEST(HalfEncode, ReferenceValues) {
  EXPECT_EQ(half_of(1.f), 0x3C00);
  EXPECT_EQ(half_of(-2.f), 0xC000);
  EXPECT_EQ(half_of(65504.f), 0x7BFF);
  EXPECT_EQ(half_of(1e6f), 0x7BFF);   // clamped, not inf
  EXPECT_EQ(half_of(-1e6f), 0xFBFF);
  EXPECT_EQ(half_of(from_bits(0x7F800000u)), 0x7C00);  // inf stays inf
  EXPECT_EQ(half_of(from_bits(0xFFC12345u)), 0xFE00);  // NaN: quiet, no payload, signed
  EXPECT_EQ(half_of(5.9604645e-8f), 0x0001);            // smallest subnormal
  EXPECT_EQ(half_of(1.0009765625f), 0x3C01);
  EXPECT_EQ(half_of(1.00048828125f), 0x3C00);  // halfway: to even
  const float v[3] = {1e6f, 70000.f, 3.f};
  uint8_t out[6];
  EXPECT_EQ(encode_half_scalar(v, 3, out), 2u);
  EXPECT_TRUE(any_beyond_half_scalar(v, 3));
  EXPECT_FALSE(any_beyond_half_scalar(v + 2, 1));
}

TEST(HalfEncode, FastPathMatchesEveryFloat) {
  if (!half_encode_fast()) GTEST_SKIP() << "no F16C on this CPU: the scalar path is the only one";
  constexpr uint64_t kBlock = uint64_t(1) << 20;
  std::atomic<uint64_t> mismatches{0}, first_bad{~uint64_t(0)};
  tbb::parallel_for(uint64_t(0), (uint64_t(1) << 32) / kBlock, [&](uint64_t b) {
    if (b * kBlock >= (uint64_t(1) << 31) && b % 8 != 0) return;
    std::vector<float> in(kBlock);
    for (uint64_t i = 0; i < kBlock; ++i) in[i] = from_bits(uint32_t(b * kBlock + i));
    std::vector<uint8_t> fast(2 * kBlock), ref(2 * kBlock);
    // Odd lengths: the 8-wide loop, its scalar tail and unaligned starts all run.
    const size_t len = 1000003;
    for (size_t at = 0; at < kBlock; at += len) {
      const size_t n = std::min<size_t>(len, kBlock - at);
      if (encode_half(in.data() + at, n, fast.data() + 2 * at) != encode_half_scalar(in.data() + at, n, ref.data() + 2 * at) ||
          any_beyond_half(in.data() + at, n) != any_beyond_half_scalar(in.data() + at, n))
        ++mismatches;
    }
    if (std::memcmp(fast.data(), ref.data(), fast.size()) != 0) {
      ++mismatches;
      for (uint64_t i = 0; i < kBlock; ++i)
        if (std::memcmp(&fast[2 * i], &ref[2 * i], 2) != 0) {
          uint64_t expected = first_bad.load();
          while (b * kBlock + i < expected && !first_bad.compare_exchange_weak(expected, b * kBlock + i)) {
          }
          break;
        }
    }
  });
  EXPECT_EQ(mismatches.load(), 0u) << "first differing float bits 0x" << std::hex << first_bad.load();
}

}  // namespace
}  // namespace gibake
