// Pieces of the voxelize stage shared by its .cpp files (not part of the public API).
#pragma once
#include <tbb/task_arena.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "io/results/voxel_grid.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake {
class PreparedScene;
}

namespace gibake::voxel {

// One (voxel, triangle) overlap.
struct Fragment {
  int64_t voxel = 0;  // linear index
  uint32_t tri = 0;
};

// Triangle `tri`'s vertices in the grid's voxel space: (p - origin) / voxel_size.
inline void triangle_in_voxels(const Scene& scene, const VoxelGrid& grid, uint32_t tri, double v[3][3]) {
  const double inv = 1.0 / double(grid.voxel_size);
  for (int k = 0; k < 3; ++k) {
    const float* p = &scene.positions[size_t(scene.indices[size_t(tri) * 3 + k]) * 3];
    for (int a = 0; a < 3; ++a) v[k][a] = (double(p[a]) - double(grid.origin[a])) * inv;
  }
}

// What the channel pass needs beyond the grid and the fragments.
struct ChannelInputs {
  const Scene* scene = nullptr;
  const VoxelGrid* grid = nullptr;
  const std::vector<kernels::ShadeLight>* lights = nullptr;  // null or empty: no direct light
  const PreparedScene* prepared = nullptr;                   // for shadow rays
  float blend_cutoff = kDefaultBlendCutoff;
};

// Fills every channel of `out` (whose ijk is set) from its fragments, given in triangle order.
// Returns the number of shadow rays traced.
uint64_t fill_channels(const ChannelInputs& in, const Fragment* frags, size_t count, SurfaceVoxel& out);

// Marks empty voxels reachable from the grid border (6-connected) Exterior, the others Interior.
// `space` holds Surface (1) for surface voxels and kUnvisited for every other voxel on entry.
constexpr uint8_t kUnvisited = 3;
void flood_fill_exterior(const std::array<int32_t, 3>& dims, std::vector<uint8_t>& space);

// Signed distance field (VoxelGrid::sdf): OpenVDB's exact unsigned distance next to the
// triangles, a Euclidean distance transform over the surface voxels beyond, the sign from the
// space classification (bake/voxel/voxel_sdf.cpp).
Status compute_sdf(const Scene& scene, tbb::task_arena& arena, VoxelGrid& grid);

// Bytes of the SDF stage's working set for a grid of `voxels` voxels and `surface` surface voxels.
double sdf_bytes_estimate(double voxels, double surface);

}  // namespace gibake::voxel
