// The set-up stage of a probe bake, built side by side as tasks in one arena of --threads: the
// Embree BVH, the texture mip chains, the enclosure voxel grid and the Vulkan session (its backend
// chosen here, from the warm-up's device list and the workload). Each is deterministic on its own,
// so running them together changes no byte; it fills the stretches where one of them runs on fewer
// threads than the arena has (the voxel flood fill, the BVH's top levels, the largest textures' mips).
#pragma once
#include <tbb/task_arena.h>

#include "bake/run/backend.h"
#include "bake/run/bake_setup.h"
#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

// Call outside any arena (the Embree device is created on this thread); the tasks run in `arena`.
// On failure the first failing part in the order above names the error.
// `warmup` (optional): a device the caller started opening (bake/run/backend.h).
Status build_bake_setup(const Scene& scene, const SetupSettings& settings, VulkanWarmup* warmup,
                        const BakeSetupParts& parts, const Context& ctx, tbb::task_arena& arena, BakeSetup& out);

}  // namespace gibake
