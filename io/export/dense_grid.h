// A dense grid handed to the VDB writers beside the voxel grids (LPV SH coefficients, test
// fields). Plain data so that bake/ stages can produce them without OpenVDB.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace gibake {

// Voxel (x,y,z) covers [origin + (x,y,z)*voxel_size, +voxel_size) (origin is the min corner of voxel
// (0,0,0), as in VoxelGrid); values are `channels` (1: FloatGrid, 3: Vec3SGrid) interleaved floats
// per voxel, index x + X*(y + Y*z). Zero values are left inactive (background 0).
struct DenseGridExport {
  std::string name;
  std::array<float, 3> origin{0.f, 0.f, 0.f};
  float voxel_size = 0.f;
  std::array<int32_t, 3> dims{0, 0, 0};
  int channels = 1;
  std::vector<float> values;
  std::string units;  // optional, stored as the grid's "units" metadata
};

}  // namespace gibake
