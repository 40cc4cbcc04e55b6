// What a probe bake needs before its first ray: the Embree BVH, the texture mip chains, the
// enclosure voxel grid and the device session. The assembly builds them side by side
// (bake/pipeline/bake_setup.h); the enclosure grid alone is bake/voxel/enclosure.h.
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
  bool enclosure = true;  // make_enclosure_voxels (bake/voxel/enclosure.h; empty when settings turn the test off)
  // The Vulkan session of settings.backend (takes the warm-up when given): device, BVH, upload.
  // Nothing is built when the backend resolves to the CPU.
  bool gpu = true;
  // With gpu: the kernels that end the surface fit's paths in the probes (path_probe_field.comp,
  // probe_field_ended.comp) are made ahead too, beside the trace rather than on the fit's way.
  bool probe_field_kernels = false;
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

}  // namespace gibake
