#include "bake/ddgi/classify.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>

#include "io/inspect/mesh_diagnostics.h"

namespace gibake {

ClosedMeshCheck::ClosedMeshCheck(const Scene& scene) : own_(scene, SolidBuild::on_demand) {}

ClosedMeshCheck::ClosedMeshCheck(const Scene& scene, const std::vector<float>& rest_positions, const float pad[3])
    : own_(scene, SolidBuild::on_demand) {
  own_.build_near(rest_positions.data(), rest_positions.size() / 3, pad);
}

ClosedMeshCheck::ClosedMeshCheck(const ClosedMeshInsideTester& shared, const std::vector<float>& rest_positions,
                                 const float pad[3])
    : shared_(&shared) {
  shared.build_near(rest_positions.data(), rest_positions.size() / 3, pad);
}

const ClosedMeshInsideTester& SharedClosedMeshes::tester(const Scene& scene) const {
  std::call_once(once_, [&] { tester_ = ClosedMeshInsideTester(scene, SolidBuild::on_demand); });
  return tester_;
}

ClassifyReport ClosedMeshCheck::report(const std::vector<float>& positions, const std::vector<DdgiProbeStats>& stats,
                                       const std::vector<ProbeState>& states) const {
  ClassifyReport report;
  // A probe strictly inside a closed solid with outward normals sees that solid's back faces, so
  // only probes with some back-face hits are asked (the others count as "outside" for both).
  bool any_asked = false;
  for (const DdgiProbeStats& st : stats) any_asked = any_asked || st.backface_fraction > 0.f;
  if (!any_asked || !tester().valid()) return report;
  report.closed_mesh_checked = true;
  // The queries side by side in the calling arena (classify() is const and thread-safe); counts
  // add up the same in any order.
  const auto count = [&](const tbb::blocked_range<size_t>& r, ClassifyReport part) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      if (!(stats[i].backface_fraction > 0.f)) continue;
      const int side = tester().classify(&positions[i * 3]);
      if (side > 0) ++part.inside_by_cgal;
      if (side == 0) continue;
      const bool inside_rays = states[i] == ProbeState::Inactive;
      if (side > 0 && !inside_rays) ++part.disagreements;
      if (side < 0 && inside_rays) ++part.inactive_outside_closed;
    }
    return part;
  };
  const auto add = [](ClassifyReport a, const ClassifyReport& b) {
    a.inside_by_cgal += b.inside_by_cgal;
    a.disagreements += b.disagreements;
    a.inactive_outside_closed += b.inactive_outside_closed;
    return a;
  };
  return tbb::parallel_reduce(tbb::blocked_range<size_t>(0, stats.size(), 64), report, count, add);
}

void ray_test_states(const std::vector<DdgiProbeStats>& stats, float backface_threshold,
                     std::vector<ProbeState>& states) {
  states.assign(stats.size(), ProbeState::Active);
  for (size_t i = 0; i < stats.size(); ++i)
    if (stats[i].backface_fraction > backface_threshold) states[i] = ProbeState::Inactive;
}

ClassifyReport classify_probes(const Scene& scene, const std::vector<float>& positions,
                               const std::vector<DdgiProbeStats>& stats, float backface_threshold,
                               bool use_cgal, std::vector<ProbeState>& states) {
  ray_test_states(stats, backface_threshold, states);
  if (!use_cgal || scene.triangle_count() == 0) return ClassifyReport{};
  return ClosedMeshCheck(scene).report(positions, stats, states);
}

bool probe_in_enclosed_space(const VoxelGrid& voxels, const float position[3]) {
  int32_t v[3];
  if (!voxels.voxel_of(position, v)) return false;
  const auto space = static_cast<VoxelSpace>(voxels.space[size_t(voxels.linear(v[0], v[1], v[2]))]);
  if (space != VoxelSpace::Surface) return space == VoxelSpace::Interior;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int32_t x = v[0] + dx, y = v[1] + dy, z = v[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x >= voxels.dims[0] || y >= voxels.dims[1] || z >= voxels.dims[2]) return false;
        if (static_cast<VoxelSpace>(voxels.space[size_t(voxels.linear(x, y, z))]) == VoxelSpace::Exterior) return false;
      }
  return true;
}

}  // namespace gibake
