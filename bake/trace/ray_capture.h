// Optional record of every ray a bake traces (for benchmarks that re-trace exactly the same rays
// with plain Embree calls). Off by default; recording costs time and memory.
#pragma once
#include <cstdint>
#include <vector>

namespace gibake {

struct CapturedRay {
  float org[3];
  float dir[3];
  float tnear, tfar;
  uint32_t kind;  // one of the constants below
  static constexpr uint32_t kProbe = 0;       // closest hit (rtcIntersect1), a probe ray
  static constexpr uint32_t kShadow = 1;      // any hit (rtcOccluded1)
  static constexpr uint32_t kRelocation = 2;  // closest hit (rtcIntersect1), a relocation ray
};

// One list per probe (relocation rays, then probe rays with their shadow rays, in trace order).
using RayCapture = std::vector<std::vector<CapturedRay>>;

}  // namespace gibake
