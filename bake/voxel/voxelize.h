// The voxelize stage: Scene triangles -> VoxelGrid (io/results/voxel_grid.h).
//   1. layout: scene bounds padded by `padding` voxels on every side; memory estimate first;
//   2. occupancy: conservative triangle/voxel overlap (bake/voxel/voxel_raster.h), per fixed chunk of
//      triangles in parallel, fragments merged in triangle order (same bytes for any thread count);
//   3. channels per surface voxel (bake/voxel/voxel_channels.cpp): fragments, coverage, albedo,
//      emission, normal, anisotropic face weights and, given lights, direct irradiance;
//   4. space: 6-connected flood fill of empty voxels from the grid border -> Exterior, the rest
//      of the empty voxels -> Interior;
//   5. signed distance field (bake/voxel/voxel_sdf.cpp), optional.
#pragma once
#include <array>
#include <tbb/task_arena.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake {

class PreparedScene;

struct VoxelSettings {
  float voxel_size = 0.f;        // metres; 0: from `resolution`
  int32_t resolution = 128;      // voxels on the longest axis of the scene bounds (when voxel_size is 0)
  int32_t padding = 1;           // empty voxels added on every side (>= 1: the flood fill starts outside)
  // Voxel GI only (bake/vxgi/vxgi_align.cpp): empty voxels added below the padding on each axis,
  // moving the origin down by as many, so chosen walls fall on coarse mip texel boundaries.
  std::array<int32_t, 3> low_extra{0, 0, 0};
  uint64_t max_bytes = uint64_t(16) << 30;  // cap on the estimated working set (--max-memory)
  bool channels = true;          // albedo, emission, normal, coverage, aniso (+ direct with lights)
  bool sdf = true;               // signed distance field (VoxelGrid::sdf, bake/voxel/voxel_sdf.cpp)
  float blend_cutoff = kDefaultBlendCutoff;     // alpha cutoff of BLEND materials (coverage and shadow rays), as the DDGI bake
};

struct VoxelReport {
  std::array<int32_t, 3> dims{0, 0, 0};
  float voxel_size = 0.f;
  uint64_t triangles = 0, skipped_triangles = 0;  // skipped: non-finite vertices
  uint64_t degenerate_triangles = 0;              // zero-area (walked as segments or points)
  uint64_t fragments = 0;                         // (voxel, triangle) overlaps
  uint64_t surface_voxels = 0, interior_voxels = 0, exterior_voxels = 0;
  uint64_t shadow_rays = 0;
  uint64_t estimated_bytes = 0;
  std::vector<std::pair<std::string, double>> stage_seconds;  // in order
  double seconds_total = 0.0;
};

// Grid placement for the settings (no allocation): origin, voxel size, dims and the estimated
// working set in bytes. BadArguments for nonsense settings or an estimate over max_bytes. Its
// per-triangle passes run in `arena` when given, else on the calling thread (same result).
Status plan_voxel_grid(const Scene& scene, const VoxelSettings& settings, VoxelGrid& layout, uint64_t& estimated_bytes,
                       tbb::task_arena* arena = nullptr);

// Voxelizes without lights (direct irradiance stays 0).
Status voxelize(const Scene& scene, const VoxelSettings& settings, const Context& ctx, VoxelGrid& out,
                VoxelReport* report = nullptr);

// Voxelizes and fills `direct` with the irradiance (lux) from `lights`, visibility by Embree shadow
// rays. `prepared` may be null (an Embree scene is then built here); when given it must have been
// built from `scene`.
Status voxelize(const Scene& scene, const VoxelSettings& settings, const std::vector<kernels::ShadeLight>& lights,
                const PreparedScene* prepared, const Context& ctx, VoxelGrid& out, VoxelReport* report = nullptr);

// Voxelizes without lights inside `arena` (a caller's arena of --threads, shared with stages
// running beside this one).
Status voxelize_in(tbb::task_arena& arena, const Scene& scene, const VoxelSettings& settings, const Context& ctx,
                   VoxelGrid& out, VoxelReport* report = nullptr);

// Settings as a JSON object (VDB metadata).
std::string voxel_settings_json(const VoxelSettings& settings);

}  // namespace gibake
