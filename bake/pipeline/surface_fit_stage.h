// The surface fit as a stage of a whole bake (bake/ddgi/surface_fit.h): once every volume is
// baked (refinement by check included), points on the surfaces around the lit probes are
// path-traced (on the bake's device when it has one) and the irradiance atlases fitted to them.
// It reads every probe and the scene, so a sharded bake runs it in the finishing run
// (`--from-shards`, shard_finish.h), never in a shard.
#pragma once
#include "bake/pipeline/bake_request.h"

namespace gibake {

// Nothing when the fit is off, for a shard, or without volumes; else fits run.volumes' atlases and
// leaves its report in run.surface_fit.
Status fit_surfaces(const BakeRequest& r, const Context& ctx, BakeResult& run);

}  // namespace gibake
