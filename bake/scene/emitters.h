// Emissive triangles as lights: the table the path-traced gather samples for next-event
// estimation. A triangle is picked with probability proportional to its area times the luminance
// of its material's emission (factor x strength; textures are evaluated at the sampled point, so
// the choice only steers variance), then a point uniformly on it.
#pragma once
#include <cstdint>
#include <vector>

#include "io/scene.h"
#include "kernels/vec.h"

namespace gibake {

struct EmitterSample {
  uint32_t triangle = 0;
  float u = 0.f, v = 0.f;     // barycentrics (Embree convention)
  kernels::float3 position;
  kernels::float3 normal;     // unit geometric normal of the front (counter-clockwise) side
  float pdf_area = 0.f;       // selection probability / triangle area, per m^2
};

class EmitterTable {
 public:
  EmitterTable() = default;
  explicit EmitterTable(const Scene& scene);

  bool empty() const { return triangles_.empty(); }
  size_t size() const { return triangles_.size(); }
  // Area density of sampling a point on triangle `tri` (0 for triangles that are not sampled).
  float pdf_area(uint32_t tri) const { return tri < pdf_area_.size() ? pdf_area_[tri] : 0.f; }
  // Picks a triangle with u0 and a point on it with (u1, u2); all in [0,1).
  EmitterSample sample(float u0, float u1, float u2) const;
  // The sampled triangles and the inclusive prefix sums of their weights (for the GPU's copy).
  const std::vector<uint32_t>& triangles() const { return triangles_; }
  const std::vector<double>& cdf() const { return cdf_; }

 private:
  const Scene* scene_ = nullptr;
  std::vector<uint32_t> triangles_;  // emissive triangles with non-zero area
  std::vector<double> cdf_;          // inclusive prefix sums of the weights, last = 1
  std::vector<float> pdf_area_;      // per scene triangle
};

}  // namespace gibake
