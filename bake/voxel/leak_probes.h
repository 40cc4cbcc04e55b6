// Which thin-wall regions of the leak audit a bake's probes actually blend across. A region only
// leaks when a shading point on one side interpolates active probes of both sides: the corner
// probes of the probe cell around each side's point are tested with a ray from the point (a probe
// the ray cannot reach sits across the wall). The inside of a closed box whose probes are all
// inactive blends nothing and is not worth a warning. Regions are ranked by how much light
// could leak: the brightest difference, in the probes' DC radiance, across the wall.
#pragma once
#include <vector>

#include "bake/scene/prepare.h"
#include "bake/voxel/leak_audit.h"
#include "io/results/ddgi_result.h"

namespace gibake {

struct LeakExposure {
  size_t region = 0;           // index into LeakAudit::regions
  int probes_across = 0;       // active corner probes across the wall from a side's point that also
                               // has active probes on its own side
  float radiance_across = 0.f; // cd/m^2: the largest DC luminance difference across the wall
};

// One entry per region of `audit`, in the region order; deterministic.
std::vector<LeakExposure> leak_exposure(const LeakAudit& audit, const DdgiResult& probes,
                                        const PreparedScene& prepared);

// The regions with probes across, most light first (ties: larger region first).
std::vector<LeakExposure> ranked_exposed(const std::vector<LeakExposure>& all);

}  // namespace gibake
