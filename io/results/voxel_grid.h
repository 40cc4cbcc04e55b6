// The voxelized scene: output of the voxelize stage (bake/voxel/voxelize.h), read by the probe bake
// (enclosed-space test), the LPV bake (geometry volume, injection), the leak audit and the VDB
// export. Plain data. Voxel (i,j,k) covers [origin + (i,j,k)*voxel_size, origin + (i+1,j+1,k+1)*voxel_size).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace gibake {

// What fills a voxel. Surface: some triangle overlaps the voxel (conservative, separating-axis
// test). Exterior: empty and reachable from outside the grid through empty voxels (6-connected
// flood fill). Interior: empty and not reachable: the inside of closed shapes or closed rooms.
enum class VoxelSpace : uint8_t { Exterior = 0, Surface = 1, Interior = 2 };

// Per surface voxel, accumulated over the triangle fragments that overlap it.
struct SurfaceVoxel {
  int32_t ijk[3] = {0, 0, 0};
  uint32_t fragments = 0;      // overlapping triangles
  float coverage = 0.f;        // 0..1: projected area of the fragments over the voxel's face area, clamped
  float albedo[3] = {0, 0, 0}; // average linear base colour (textures at the fragments' UVs)
  float emission[3] = {0, 0, 0};   // average emitted radiance, cd/m^2
  float normal[3] = {0, 0, 0};     // average unit normal (area weighted)
  float direct[3] = {0, 0, 0};     // direct irradiance from the scene's lights, lux
  float aniso[6] = {0, 0, 0, 0, 0, 0};  // face weights +x -x +y -y +z -z (share of the surface facing each way)
};

struct VoxelGrid {
  std::array<float, 3> origin{0.f, 0.f, 0.f};  // world position of voxel (0,0,0)'s min corner, metres
  float voxel_size = 0.f;                       // metres
  std::array<int32_t, 3> dims{0, 0, 0};
  std::vector<uint8_t> space;                   // dims product, VoxelSpace, index x + X*(y + Y*z)
  std::vector<SurfaceVoxel> surface;            // sorted by linear index
  // Signed distance (metres) from each voxel centre to the nearest surface, dense like `space`;
  // negative in Interior space (bake/voxel/voxel_sdf.cpp says how the sign is chosen). Empty when the
  // voxelize stage was asked for no SDF.
  std::vector<float> sdf;

  bool empty() const { return dims[0] <= 0 || dims[1] <= 0 || dims[2] <= 0; }
  int64_t linear(int32_t x, int32_t y, int32_t z) const {
    return int64_t(x) + int64_t(dims[0]) * (int64_t(y) + int64_t(dims[1]) * int64_t(z));
  }
  // Voxel containing a world position; false outside the grid.
  bool voxel_of(const float p[3], int32_t ijk[3]) const {
    if (empty() || !(voxel_size > 0.f)) return false;
    for (int a = 0; a < 3; ++a) {
      const float f = std::floor((p[a] - origin[a]) / voxel_size);
      if (!(f >= 0.f) || f >= float(dims[a])) return false;
      ijk[a] = static_cast<int32_t>(f);
    }
    return true;
  }
  // World position of voxel (x,y,z)'s centre: origin + (ijk + 0.5) * voxel_size.
  std::array<float, 3> voxel_center(int32_t x, int32_t y, int32_t z) const {
    return {origin[0] + (float(x) + 0.5f) * voxel_size, origin[1] + (float(y) + 0.5f) * voxel_size,
            origin[2] + (float(z) + 0.5f) * voxel_size};
  }
  // The surface voxel at (x,y,z), or null (binary search in `surface`).
  const SurfaceVoxel* find_surface(int32_t x, int32_t y, int32_t z) const {
    if (x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] || z >= dims[2]) return nullptr;
    const int64_t key = linear(x, y, z);
    size_t lo = 0, hi = surface.size();
    while (lo < hi) {
      const size_t mid = lo + (hi - lo) / 2;
      const SurfaceVoxel& s = surface[mid];
      const int64_t k = linear(s.ijk[0], s.ijk[1], s.ijk[2]);
      if (k == key) return &s;
      if (k < key) lo = mid + 1;
      else hi = mid;
    }
    return nullptr;
  }
  // Space at a world position; Exterior outside the grid.
  VoxelSpace space_at(const float p[3]) const {
    int32_t v[3];
    if (!voxel_of(p, v)) return VoxelSpace::Exterior;
    return static_cast<VoxelSpace>(space[size_t(linear(v[0], v[1], v[2]))]);
  }
};

}  // namespace gibake
