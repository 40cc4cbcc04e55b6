// The leak-audit driver shared by the bake (bake/pipeline/) and `gibake inspect`: audits the voxel grid against
// the probe grid's coarsest spacing and warns. Before a bake (inspect) about the largest regions;
// after a bake only about those its active probes blend across, most light first. The rest are a
// count; every region stays available for the report and JSON (leak_json).
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "bake/scene/prepare.h"
#include "bake/voxel/leak_audit.h"
#include "bake/voxel/leak_probes.h"
#include "io/results/ddgi_result.h"
#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake {

// The coarsest axis spacing of a probe grid (0 for a single probe: nothing to blend across).
float coarsest_spacing(const std::array<float, 3>& spacing);

// Before a bake (inspect): runs the audit when `probe_spacing` > 0 (else leaves `out` empty and
// returns ok) and warns about its largest regions. `ran` tells the caller whether it ran.
Status audit_and_warn(const VoxelGrid& voxels, const PreparedScene& prepared,
                      const std::vector<kernels::ShadeLight>& lights, float probe_spacing, const Context& ctx,
                      LeakAudit& out, bool& ran);

// After a bake: every region (`out` keeps them all, for the report and JSON), `exposure` one entry
// per region; warnings only for the regions the bake's active probes blend across, most light first.
Status audit_bake_leaks(const VoxelGrid& voxels, const PreparedScene& prepared,
                        const std::vector<kernels::ShadeLight>& lights, const DdgiResult& probes, const Context& ctx,
                        LeakAudit& out, std::vector<LeakExposure>& exposure, bool& ran);

// One line per region for the report: where, and whether (and how much) active probes blend across.
std::vector<std::string> leak_region_lines(const LeakAudit& audit, const std::vector<LeakExposure>& exposure);

// Every region with its bounds, points and (after a bake) the active probes across it, as the
// --progress json summary and inspect --format json give it. `exposure` may be null (inspect).
nlohmann::json leak_json(const LeakAudit& audit, const std::vector<LeakExposure>* exposure);

}  // namespace gibake
