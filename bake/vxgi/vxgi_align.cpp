// Thin walls on coarse texel boundaries (vxgi_wall_alignment in vxgi.h). With split sides a
// double-sided wall is two voxel layers, one per side, whose boundary is the voxel boundary nearest
// the wall. A mip texel holding both layers averages them on its faces along the wall, so a cone
// from the dark side reads the lit side there (docs/BENCHMARKS.md, "Voxel GI"). The
// layers stay in separate texels up to level L when their boundary index is a multiple of 2^L; an
// offline baker may pick the grid's origin for that, per axis, weighing each double-sided wall
// facing along the axis by its area and by how differently the lights reach its two sides.
#include <cmath>
#include <map>

#include "bake/scene/material.h"
#include "kernels/shade.h"
#include "bake/vxgi/vxgi.h"

namespace gibake {

namespace {

int trailing_zeros(int64_t n, int cap) {
  int c = 0;
  while (c < cap && (n == 0 || n % 2 == 0)) {
    n /= 2;
    ++c;
  }
  return c;
}

// Direct illuminance (luminance-weighted lux) on the side of the surface at p facing `side`, from
// every light, with shadows.
double side_illuminance(const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                        const kernels::float3& p, const kernels::float3& side, float eps) {
  double e = 0.0;
  for (const kernels::ShadeLight& light : lights) {
    kernels::LightSample ls;
    if (!kernels::sample_light(light, p, ls)) continue;
    const float c = side.x * ls.to_light.x + side.y * ls.to_light.y + side.z * ls.to_light.z;
    if (c <= 0.f) continue;
    const kernels::float3 o{p.x + side.x * eps, p.y + side.y * eps, p.z + side.z * eps};
    if (prepared.occluded(o, ls.to_light, 0.f, ls.distance)) continue;
    e += double(c) * (0.2126 * ls.illuminance.x + 0.7152 * ls.illuminance.y + 0.0722 * ls.illuminance.z);
  }
  return e;
}

}  // namespace

std::array<int32_t, 3> vxgi_wall_alignment(const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                                           const VoxelGrid& layout, int levels) {
  const Scene& scene = prepared.scene();
  std::array<int32_t, 3> shift{0, 0, 0};
  if (levels < 1 || !(layout.voxel_size > 0.f)) return shift;
  std::map<int64_t, double> area[3];  // boundary index -> wall area, per axis
  for (uint32_t t = 0; t < uint32_t(scene.triangle_count()); ++t) {
    if (!triangle_material(scene, t).double_sided) continue;  // single-sided: one layer, nothing to split
    double p[3][3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) p[k][a] = scene.positions[size_t(scene.indices[size_t(t) * 3 + size_t(k)]) * 3 + size_t(a)];
    const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0) || !std::isfinite(len)) continue;
    for (int a = 0; a < 3; ++a) {
      if (std::fabs(n[a]) < 0.999 * len) continue;
      // Weight: area x the difference between the sides' direct light at 4 points (the centroid and
      // half-way to each corner), plus a trace of area for scenes lit only by emitters.
      kernels::float3 side{0.f, 0.f, 0.f};
      (&side.x)[a] = 1.f;
      double contrast = 0.0;
      for (int k = -1; k < 3; ++k) {
        kernels::float3 q{0.f, 0.f, 0.f};
        for (int c = 0; c < 3; ++c) {
          const double centroid = (p[0][c] + p[1][c] + p[2][c]) / 3.0;
          (&q.x)[c] = float(k < 0 ? centroid : 0.5 * (centroid + p[k][c]));
        }
        const float eps = 1e-3f * layout.voxel_size;
        contrast += std::fabs(side_illuminance(prepared, lights, q, side, eps) -
                              side_illuminance(prepared, lights, q, -side, eps)) / 4.0;
      }
      const double u = (p[0][a] - double(layout.origin[size_t(a)])) / double(layout.voxel_size);
      area[a][int64_t(std::llround(u))] += 0.5 * len * (contrast + 1e-6);
    }
  }
  const int span = 1 << levels;
  for (int a = 0; a < 3; ++a) {
    double best = -1.0;
    for (int s = 0; s < span; ++s) {  // the smallest shift among the best scores (fewest voxels added)
      double score = 0.0;
      for (const auto& [b, w] : area[a]) score += w * trailing_zeros(b + s, levels);
      if (score > best + 1e-9 * (score + 1.0)) {
        best = score;
        shift[size_t(a)] = s;
      }
    }
  }
  return shift;
}

}  // namespace gibake
