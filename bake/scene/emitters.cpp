#include "bake/scene/emitters.h"

#include <algorithm>
#include <cmath>

#include "bake/scene/material.h"
#include "kernels/path.h"

namespace gibake {
using kernels::float3;

namespace {
float3 vertex(const Scene& s, uint32_t tri, int k) { return kernels::load3(&s.positions[size_t(s.indices[tri * 3 + k]) * 3]); }
}  // namespace

EmitterTable::EmitterTable(const Scene& scene) : scene_(&scene) {
  const size_t tris = scene.triangle_count();
  std::vector<double> weight;
  for (uint32_t t = 0; t < tris; ++t) {
    const Material& m = triangle_material(scene, t);
    if (!m.is_emissive()) continue;
    const float3 e1 = vertex(scene, t, 1) - vertex(scene, t, 0), e2 = vertex(scene, t, 2) - vertex(scene, t, 0);
    const double area = 0.5 * double(kernels::length(kernels::cross(e1, e2)));
    const double lum = (0.2126 * m.emissive[0] + 0.7152 * m.emissive[1] + 0.0722 * m.emissive[2]) * m.emissive_strength;
    // A coloured emitter of zero luminance still emits; keep a floor so it can be sampled.
    const double w = area * std::max(lum, 1e-3 * std::max({m.emissive[0], m.emissive[1], m.emissive[2]}) * m.emissive_strength);
    if (!(w > 0.0) || !std::isfinite(w)) continue;
    triangles_.push_back(t);
    weight.push_back(w);
  }
  if (triangles_.empty()) return;
  double total = 0.0;
  for (double w : weight) total += w;
  cdf_.resize(weight.size());
  pdf_area_.assign(tris, 0.f);
  double run = 0.0;
  for (size_t i = 0; i < weight.size(); ++i) {
    run += weight[i];
    cdf_[i] = run / total;
    const uint32_t t = triangles_[i];
    const float3 e1 = vertex(scene, t, 1) - vertex(scene, t, 0), e2 = vertex(scene, t, 2) - vertex(scene, t, 0);
    const double area = 0.5 * double(kernels::length(kernels::cross(e1, e2)));
    pdf_area_[t] = static_cast<float>(weight[i] / total / area);
  }
  cdf_.back() = 1.0;
}

EmitterSample EmitterTable::sample(float u0, float u1, float u2) const {
  const size_t i = std::min<size_t>(size_t(std::upper_bound(cdf_.begin(), cdf_.end(), double(u0)) - cdf_.begin()),
                                    triangles_.size() - 1);
  EmitterSample s;
  s.triangle = triangles_[i];
  kernels::sample_triangle_barycentrics(u1, u2, s.u, s.v);
  const float3 a = vertex(*scene_, s.triangle, 0), b = vertex(*scene_, s.triangle, 1), c = vertex(*scene_, s.triangle, 2);
  s.position = a * (1.f - s.u - s.v) + b * s.u + c * s.v;
  s.normal = kernels::normalize(kernels::cross(b - a, c - a));
  s.pdf_area = pdf_area_[s.triangle];
  return s;
}

}  // namespace gibake
