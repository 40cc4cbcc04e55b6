#include "bake/classify.h"

#include "io/mesh_diagnostics.h"

namespace gibake {

ClassifyReport classify_probes(const Scene& scene, const std::vector<float>& positions,
                               const std::vector<DdgiProbeStats>& stats, float backface_threshold,
                               bool use_cgal, std::vector<ProbeState>& states) {
  ClassifyReport report;
  const size_t n = stats.size();
  states.assign(n, ProbeState::Active);
  for (size_t i = 0; i < n; ++i)
    if (stats[i].backface_fraction > backface_threshold) states[i] = ProbeState::Inactive;
  if (!use_cgal || scene.triangle_count() == 0) return report;
  // A probe strictly inside a closed solid with outward normals sees that solid's back faces, so
  // only probes with some back-face hits are asked (the others count as "outside" for both).
  bool any = false;
  for (size_t i = 0; i < n; ++i) any = any || stats[i].backface_fraction > 0.f;
  if (!any) return report;
  ClosedMeshInsideTester tester(scene);
  if (!tester.valid()) return report;
  report.closed_mesh_checked = true;
  for (size_t i = 0; i < n; ++i) {
    if (stats[i].backface_fraction <= 0.f) continue;
    const int side = tester.classify(&positions[i * 3]);
    if (side > 0) ++report.inside_by_cgal;
    if (side == 0) continue;
    const bool inside_rays = states[i] == ProbeState::Inactive;
    if (side > 0 && !inside_rays) ++report.disagreements;
    if (side < 0 && inside_rays) ++report.inactive_outside_closed;
  }
  return report;
}

}  // namespace gibake
