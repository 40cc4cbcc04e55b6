#include "bake/voxel/enclosure.h"

#include "bake/voxel/voxelize.h"

namespace gibake {

Status make_enclosure_voxels(const Scene& scene, const SetupSettings& s, const Context& ctx, VoxelGrid& out,
                             tbb::task_arena* arena) {
  out = VoxelGrid{};
  if (s.enclosure_resolution <= 0 || scene.bounds.empty()) return Status::ok();
  VoxelSettings vs;
  vs.resolution = s.enclosure_resolution;
  vs.channels = false;
  vs.sdf = false;
  vs.blend_cutoff = s.blend_cutoff;
  return arena ? voxelize_in(*arena, scene, vs, ctx, out) : voxelize(scene, vs, ctx, out);
}

}  // namespace gibake
