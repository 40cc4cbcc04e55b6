// The enclosure voxel grid a probe bake's inside test and default grid read: occupancy and the
// flood fill only, at the set-up's enclosure resolution.
#pragma once
#include <tbb/task_arena.h>

#include "bake/run/bake_setup.h"
#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

// The grid the enclosure test voxelizes when the caller gives none: enclosure_resolution voxels on
// the longest side. `out` stays empty when the test is off. In `arena` when given (shared with the
// tasks beside it), otherwise in one of ctx.threads.
Status make_enclosure_voxels(const Scene& scene, const SetupSettings& settings, const Context& ctx, VoxelGrid& out,
                             tbb::task_arena* arena = nullptr);

}  // namespace gibake
