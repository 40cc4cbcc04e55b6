// The surface fit's kept paths (bake/trace/kept_hits.h) ended in a probe field, as
// trace_surface_irradiance would end the same paths in it.
#pragma once
#include <vector>

#include "bake/trace/kept_hits.h"
#include "io/context.h"

namespace gibake {

struct SurfaceLight;  // reconstruction_check.h

// The kept paths ended in `field`: `out`'s probe_lit and probe_half (nothing else) as
// trace_surface_irradiance gives them with `field`, to rounding. `out` has a light per kept point.
// Sums in path order per point: the same for any thread count.
void end_kept_paths(const EndedPathHits& kept, const ProbeField& field, const Context& ctx,
                    std::vector<SurfaceLight>& out);

}  // namespace gibake
