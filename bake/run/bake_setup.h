// The set-up stage of a probe bake: what it needs before its first ray, built side by side as
// tasks in one arena of --threads: the Embree BVH, the texture mip chains and the enclosure voxel
// grid. Each is deterministic on its own, so running them together changes no byte; it fills the
// stretches where one of them runs on fewer threads than the arena has (the voxel flood fill, the
// BVH's top levels, the largest textures' mips).
#pragma once
#include <tbb/task_arena.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bake/run/backend.h"
#include "bake/scene/prepare.h"
#include "bake/scene/texture_lod.h"
#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct GpuSession;

// What the set-up reads of a bake's settings.
struct SetupSettings {
  float blend_cutoff = kDefaultBlendCutoff;  // alphaMode BLEND traced as MASK with this cutoff; 0: opaque
  int32_t enclosure_resolution = 0;          // voxels on the longest side of the enclosure grid; 0: none
  BackendSettings backend;
};

struct BakeSetupParts {
  bool bvh = true;        // PreparedScene with settings.blend_cutoff
  bool mips = true;       // TextureLod
  bool enclosure = true;  // make_enclosure_voxels (stays empty when settings turn the test off)
  // The Vulkan session of settings.backend (takes the warm-up when given): device, BVH, upload.
  // Nothing is built when the backend resolves to the CPU.
  bool gpu = true;
};

struct BakeSetup {
  BakeSetup();
  ~BakeSetup();
  BakeSetup(BakeSetup&&) noexcept;
  BakeSetup& operator=(BakeSetup&&) noexcept;

  std::unique_ptr<PreparedScene> prepared;
  TextureLod lod;
  VoxelGrid voxels;
  std::shared_ptr<GpuSession> gpu;  // with the gpu part: the session (empty on the CPU backend)
  // "prepare", "voxelize (enclosure)", "texture mips", "vulkan (BVH, upload)" (each task's own
  // time, for the parts built) and "set-up (side by side)", the wall time of the whole stage.
  std::vector<std::pair<std::string, double>> stage_seconds;
};

// The grid the enclosure test voxelizes when the caller gives none: occupancy and the flood fill
// only, enclosure_resolution voxels on the longest side. `out` stays empty when the test is off.
// In `arena` when given (shared with the tasks beside it), otherwise in one of ctx.threads.
Status make_enclosure_voxels(const Scene& scene, const SetupSettings& settings, const Context& ctx, VoxelGrid& out,
                             tbb::task_arena* arena = nullptr);

// Call outside any arena (the Embree device is created on this thread); the tasks run in `arena`.
// On failure the first failing part in the order above names the error.
// `warmup` (optional): a device the caller started opening (bake/run/backend.h).
Status build_bake_setup(const Scene& scene, const SetupSettings& settings, VulkanWarmup* warmup,
                        const BakeSetupParts& parts, const Context& ctx, tbb::task_arena& arena, BakeSetup& out);

}  // namespace gibake
