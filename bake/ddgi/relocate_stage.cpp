#include "bake/ddgi/relocate_stage.h"

#include <array>

namespace gibake {

Status relocate_probes(const RelocationStage& st, DdgiDevice& device, const std::vector<int32_t>& probes,
                       const Context& ctx, std::vector<float>& offsets, std::vector<uint8_t>& moved,
                       std::vector<uint64_t>& rays) {
  // Each probe's sums of a pass: count its rays and move it (probes are disjoint, so passes may
  // hand them over from several threads).
  const RelocationDone apply = [&](int32_t p, const RelocationSums& sums, uint64_t traced) {
    rays[p] += traced;
    std::array<float, 3> off{offsets[p * 3], offsets[p * 3 + 1], offsets[p * 3 + 2]};
    if (apply_relocation(sums, st.params, off)) {
      for (int a = 0; a < 3; ++a) offsets[p * 3 + a] = off[a];
      moved[p] = 1;
    }
  };
  RelocationRays geometry = st.rays;
  geometry.threshold = st.params.threshold;
  geometry.passes = st.iterations;
  GIBAKE_TRY(device.begin_relocation(geometry));
  for (int iter = 0; iter < st.iterations; ++iter)
    GIBAKE_TRY(device.relocation_pass(probes, kRelocatePassBase + uint32_t(iter), ctx, apply));
  return Status::ok();
}

}  // namespace gibake
