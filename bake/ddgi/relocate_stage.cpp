#include "bake/ddgi/relocate_stage.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>

namespace gibake {

Status relocate_probes(const RelocationStage& st, DdgiDevice& device, const std::vector<int32_t>& probes,
                       const Context& ctx, std::vector<float>& offsets, std::vector<uint8_t>& moved,
                       std::vector<uint64_t>& rays) {
  // Each probe's sums of a pass: count its rays and move it, never through a surface (probes are
  // disjoint, so passes may hand them over from several threads; the check traces on the CPU
  // whatever the device).
  const PreparedScene* scene = st.rays.setup.prepared;
  const RelocationDone apply = [&](int32_t p, const RelocationSums& sums, uint64_t traced) {
    rays[p] += traced;
    const std::array<float, 3> old{offsets[p * 3], offsets[p * 3 + 1], offsets[p * 3 + 2]};
    std::array<float, 3> off = old;
    if (!apply_relocation(sums, st.params, off)) return;
    if (scene) {
      const kernels::float3 from = st.rays.position(p);
      const float on_surface = on_surface_distance(from, st.params.threshold);
      if (keep_side(*scene, from, old, st.params, on_surface, off) && off == old) return;  // no safe move
    }
    for (int a = 0; a < 3; ++a) offsets[p * 3 + a] = off[a];
    moved[p] = 1;
  };
  // Probes on a surface first leave it to its front (before their rays, which would leave from
  // whichever side rounding chose). Each probe reads and writes only its own entries, so the order
  // of the probes does not change the result.
  if (scene)
    tbb::parallel_for(tbb::blocked_range<size_t>(0, probes.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const int32_t p = probes[i];
        const kernels::float3 rest = st.rays.position(p);
        std::array<float, 3> off{offsets[p * 3], offsets[p * 3 + 1], offsets[p * 3 + 2]};
        if (!leave_surface(*scene, rest, on_surface_distance(rest, st.params.threshold), off)) continue;
        for (int a = 0; a < 3; ++a) offsets[p * 3 + a] = off[a];
        moved[p] = 1;
      }
    });
  RelocationRays geometry = st.rays;
  geometry.threshold = st.params.threshold;
  geometry.passes = st.iterations;
  GIBAKE_TRY(device.begin_relocation(geometry));
  for (int iter = 0; iter < st.iterations; ++iter)
    GIBAKE_TRY(device.relocation_pass(probes, kRelocatePassBase + uint32_t(iter), ctx, apply));
  device.end_relocation();
  return Status::ok();
}

}  // namespace gibake
