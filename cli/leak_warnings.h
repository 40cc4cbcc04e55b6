// The leak-audit driver shared by `gibake bake` and `gibake inspect`: audits the voxel grid against
// the probe grid's coarsest spacing and prints one warning per region (the largest first) plus a
// count of the smaller ones left out.
#pragma once

#include <vector>

#include "bake/scene/prepare.h"
#include "bake/voxel/leak_audit.h"
#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake::cli {

// The coarsest axis spacing of a probe grid (0 for a single probe: nothing to blend across).
float coarsest_spacing(const std::array<float, 3>& spacing);

// Runs the audit when `probe_spacing` > 0 (else leaves `out` empty and returns ok) and warns.
// `ran` tells the caller whether it ran.
Status audit_and_warn(const VoxelGrid& voxels, const PreparedScene& prepared,
                      const std::vector<kernels::ShadeLight>& lights, float probe_spacing, const Context& ctx,
                      LeakAudit& out, bool& ran);

}  // namespace gibake::cli
