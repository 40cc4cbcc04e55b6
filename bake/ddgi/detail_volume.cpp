#include "bake/ddgi/detail_volume.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace gibake {

namespace {

constexpr int32_t kRaisedAbove = 1;  // voxels above the column's lowest surface that still count as ground

// The cluster padded by `pad` on every side, the ground's side too: the runtime blend gives a volume
// its full weight only from one spacing inside its cell box (docs/FORMAT.md "Several volumes"), so
// the house's floor and outer walls need that much of the volume around them (the layer below the
// ground goes inactive, as probes under a floor do).
void pad_box(const RaisedCluster& c, float pad, std::array<float, 3>& lo, std::array<float, 3>& hi) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = c.lo[a] - pad;
    hi[a] = c.hi[a] + pad;
  }
}

// The default grid's box: its cells, or the scene's extent on an axis with one probe.
double grid_box_volume(const DdgiVolumeDesc& d, const Bounds& scene) {
  double v = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double e = d.counts[a] > 1 ? double(d.counts[a]) * d.spacing[a] : double(scene.max[a] - scene.min[a]);
    v *= std::max(e, 1e-6);
  }
  return v;
}

}  // namespace

RaisedCluster find_raised_cluster(const VoxelGrid& v, const Bounds& scene) {
  RaisedCluster c;
  if (v.empty() || !(v.voxel_size > 0.f) || scene.empty() ||
      v.space.size() != size_t(v.dims[0]) * v.dims[1] * v.dims[2])
    return c;
  std::array<int32_t, 3> u0{v.dims[0], v.dims[1], v.dims[2]}, u1{0, 0, 0};
  int32_t ground = v.dims[1];  // lowest surface under the raised columns
  for (int32_t z = 0; z < v.dims[2]; ++z)
    for (int32_t x = 0; x < v.dims[0]; ++x) {
      int32_t lowest = -1, top = -1;
      for (int32_t y = 0; y < v.dims[1]; ++y) {
        if (v.space[size_t(v.linear(x, y, z))] != uint8_t(VoxelSpace::Surface)) continue;
        if (lowest < 0) lowest = y;
        if (y > lowest + kRaisedAbove) top = y, ++c.voxels;
      }
      if (top < 0) continue;
      u0[0] = std::min(u0[0], x), u1[0] = std::max(u1[0], x + 1);
      u0[2] = std::min(u0[2], z), u1[2] = std::max(u1[2], z + 1);
      u1[1] = std::max(u1[1], top + 1);
      ground = std::min(ground, lowest);
    }
  if (c.voxels == 0) return c;
  u0[1] = ground;
  c.found = true;
  for (int a = 0; a < 3; ++a) {
    c.lo[a] = std::clamp(v.origin[a] + float(u0[a]) * v.voxel_size, scene.min[a], scene.max[a]);
    c.hi[a] = std::clamp(v.origin[a] + float(u1[a]) * v.voxel_size, scene.min[a], scene.max[a]);
  }
  return c;
}

uint64_t box_grid_probes(const std::array<float, 3>& lo, const std::array<float, 3>& hi, float spacing) {
  uint64_t n = 1;
  for (int a = 0; a < 3; ++a) n *= uint64_t(std::max(1.0, std::ceil(double(hi[a] - lo[a]) / spacing - 1e-4)));
  return n;
}

GridSettings box_grid_settings(const GridSettings& base, const std::array<float, 3>& lo,
                               const std::array<float, 3>& hi, float spacing) {
  GridSettings g = base;
  g.spacing = 0.f;
  g.padding = 0.f;
  g.explicit_bounds = true;
  g.fit_to_voxels = false;
  for (int a = 0; a < 3; ++a) {
    const double cells = std::max(1.0, std::ceil(double(hi[a] - lo[a]) / spacing - 1e-4));
    const double centre = 0.5 * (double(lo[a]) + hi[a]), half = 0.5 * (cells - 1.0) * spacing;
    g.counts[a] = int32_t(cells);
    g.grid_min[a] = float(centre - half);
    g.grid_max[a] = float(centre + half);
  }
  return g;
}

DetailDecision decide_detail_volume(const VoxelGrid& voxels, const Bounds& scene, const DdgiVolumeDesc& d,
                                    const GridSettings& grid, uint64_t budget, const DetailRule& rule) {
  DetailDecision out;
  out.cluster = find_raised_cluster(voxels, scene);
  out.default_spacing = std::max({d.spacing[0], d.spacing[1], d.spacing[2]});
  if (!out.cluster.found) {
    out.text = "no raised geometry in the voxels: one grid";
    return out;
  }
  const RaisedCluster& c = out.cluster;
  const std::array<float, 3> extent{c.hi[0] - c.lo[0], c.hi[1] - c.lo[1], c.hi[2] - c.lo[2]};
  GridSettings g = grid;
  g.auto_max_probes = std::max<uint64_t>(1, budget);
  float s = default_probe_spacing(extent, g);
  pad_box(c, s, out.lo, out.hi);
  while (box_grid_probes(out.lo, out.hi, s) > g.auto_max_probes) {
    s *= 1.05f;
    pad_box(c, s, out.lo, out.hi);
  }
  out.spacing = s;
  out.probes = box_grid_probes(out.lo, out.hi, s);
  out.fraction = float(double(std::max(extent[0], 1e-6f)) * std::max(extent[1], 1e-6f) * std::max(extent[2], 1e-6f) /
                       grid_box_volume(d, scene));
  const float ratio = s > 0.f ? out.default_spacing / s : 0.f;
  out.add = ratio >= rule.min_ratio && out.fraction <= rule.max_fraction;
  char text[320];
  std::snprintf(text, sizeof text,
                "raised geometry (%.3g x %.3g x %.3g m, %.3g%% of the default grid's box) needs %.3g m, the default "
                "grid has %.3g m (%.2gx): %s",
                double(extent[0]), double(extent[1]), double(extent[2]), 100.0 * out.fraction, double(s),
                double(out.default_spacing), double(ratio),
                out.add ? "detail volume added"
                        : ratio < rule.min_ratio ? "one grid serves" : "the cluster fills the scene, one grid serves");
  out.text = text;
  return out;
}

}  // namespace gibake
