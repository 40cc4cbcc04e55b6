#include "cli/leak_warnings.h"

#include <algorithm>
#include <string>

namespace gibake::cli {

float coarsest_spacing(const std::array<float, 3>& spacing) {
  float coarsest = 0.f;
  for (float sp : spacing) coarsest = std::max(coarsest, sp);
  return coarsest;
}

Status audit_and_warn(const VoxelGrid& voxels, const PreparedScene& prepared,
                      const std::vector<kernels::ShadeLight>& lights, float probe_spacing, const Context& ctx,
                      LeakAudit& out, bool& ran) {
  ran = false;
  if (!(probe_spacing > 0.f)) return Status::ok();
  LeakAuditSettings ls;
  ls.probe_spacing = probe_spacing;
  GIBAKE_TRY(audit_leaks(voxels, prepared, lights, ls, ctx, out));
  for (const LeakRegion& r : out.regions) ctx.warning(describe_leak(r, ls.probe_spacing));
  if (out.regions_total > out.regions.size())
    ctx.warning("leak risk: " + std::to_string(out.regions_total - out.regions.size()) +
                " more thin-wall regions between lit and unlit space (smaller than those above)");
  ran = true;
  return Status::ok();
}

}  // namespace gibake::cli
