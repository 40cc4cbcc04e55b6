// What a bake run builds or is handed, kept apart from what the user chose (the *Settings
// structs): the shared set-up (Embree BVH, texture mips, voxel grid), the Vulkan session and its
// warm-up, and benchmark hooks. Every member is optional: a bake builds what it is not given, so a
// caller that bakes several kinds from one scene builds each part once and hands it to all of them.
// Nothing here is part of a settings JSON or changes a result's bytes.
#pragma once
#include "bake/trace/ray_capture.h"

namespace gibake {

struct VoxelGrid;
struct PlacedGrid;
class PreparedScene;
class TextureLod;
struct GpuSession;
struct BakeSetup;
class VulkanWarmup;
struct DdgiShardRun;
class DdgiPlatform;
class BakeFileStream;
class SharedClosedMeshes;

struct RunContext {
  // A voxel grid of the same scene (bake/voxel/voxelize.h); the DDGI enclosure test reads it.
  // Null: the bake voxelizes the scene itself at its enclosure resolution.
  const VoxelGrid* voxels = nullptr;
  // The volume's grid, placed by the caller from the same grid settings (bake/ddgi/volume_plan.h
  // places each volume's once). Null: the bake places it, fitting the default grid to voxels it builds.
  const PlacedGrid* placed = nullptr;
  // An Embree scene built from the same scene with the same blend cutoff.
  const PreparedScene* prepared = nullptr;
  // Texture mip chains of the same scene (bake/scene/texture_lod.h).
  const TextureLod* texture_lod = nullptr;
  // The Vulkan session opened for the settings' backend (bake/pipeline/bake_setup.h).
  GpuSession* gpu_session = nullptr;
  // Where the parts the bake builds itself (those not given above) are left for the caller, e.g.
  // the enclosure grid for a leak audit after the bake; null: freed with the bake.
  BakeSetup* setup_out = nullptr;
  // A Vulkan device the caller started opening before the import (bake/run/backend.h).
  VulkanWarmup* vulkan_warmup = nullptr;
  // Benchmarks only: every traced ray (relocation, probe, shadow) recorded per probe; slows the bake.
  RayCapture* capture_rays = nullptr;
  // `gibake bake --shard I/N`: bake only that shard's probes and hand them over instead of finishing
  // the bake (bake/ddgi/shard_bake.h); null: every probe.
  DdgiShardRun* shard = nullptr;
  // The scene's closed components for the closed-mesh check (bake/ddgi/classify.h), found once for
  // every volume of the bake; null: each bake finds them itself.
  const SharedClosedMeshes* closed_meshes = nullptr;
  // Where the set-up and the device come from (bake/ddgi/ddgi_device.h); a DDGI bake needs one.
  const DdgiPlatform* platform = nullptr;
  // The bake file begun before the trace (io/bakefile/bake_stream.h): a whole bake of one DDGI
  // volume streams its atlases into it as their rows become final; null: written after the bake only.
  BakeFileStream* file_stream = nullptr;
  // Whether a bake whose probes all saw no light warns; a refined volume (bake/ddgi/refine.h) may sit
  // wholly inside thick walls, where dark probes are right, and the default grid warns for the bake.
  bool warn_black = true;
  // Host memory the bake's other volumes hold beside this one until the file is written (their
  // results and their part of the write buffer, bake/ddgi/ddgi_memory.h): counted into this bake's
  // estimate against --max-memory.
  uint64_t held_bytes = 0;
};

}  // namespace gibake
