// Result of the voxel-GI bake (bake/vxgi/vxgi.h), written by io/bakefile as vxgi_volume +
// vxgi_radiance (+ vxgi_sdf) sections (docs/FORMAT.md, format 1.3). Plain data.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace gibake {

constexpr int kVxgiFaces = 6;  // +X, -X, +Y, -Y, +Z, -Z

// Per-axis voxel counts of mip level `level` (each axis halved, rounding up).
inline std::array<int32_t, 3> vxgi_level_dims(const std::array<int32_t, 3>& dims, int level) {
  std::array<int32_t, 3> d = dims;
  for (int l = 0; l < level; ++l)
    for (int32_t& v : d) v = (v + 1) / 2;
  return d;
}

// Levels until every axis has one voxel.
inline int vxgi_full_levels(const std::array<int32_t, 3>& dims) {
  int levels = 1;
  for (std::array<int32_t, 3> d = dims; d[0] > 1 || d[1] > 1 || d[2] > 1; ++levels) d = vxgi_level_dims(d, 1);
  return levels;
}

// One clipmap: level-0 grid and its mip chain. levels[l] holds 6 faces x voxels x RGBA floats,
// [face][z][y][x][rgba], rgb premultiplied by alpha (io/loader/include/gibake/format.h).
struct VxgiClipmap {
  std::array<float, 3> grid_min{0.f, 0.f, 0.f};  // metres
  float voxel_size = 0.f;                        // metres, level 0
  std::array<int32_t, 3> dims{0, 0, 0};          // level 0
  int faces = kVxgiFaces;  // 6, or 22 with the 16 precomputed cone slices after the faces
  std::vector<std::vector<float>> levels;  // faces x voxels x RGBA per level
  std::vector<float> sdf;  // level-0 voxels: distance (m) to the nearest opaque voxel; empty = none
  float diffuse_scale = 1.f;       // fitted against the path tracer (bake/vxgi/vxgi_calibrate.cpp)
  float calibration_error = 0.f;   // relative RMS after scaling, at the calibration points
  uint32_t calibration_points = 0;
  size_t voxel_count() const { return size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]); }
};

struct VxgiStats {
  uint64_t surface_voxels = 0, interior_voxels = 0, faces_traced = 0, faces_skipped = 0;
  uint64_t rays = 0, shadow_rays = 0, bounce_rays = 0;
  uint64_t estimated_bytes = 0;
  double seconds_voxelize = 0.0, seconds_radiance = 0.0, seconds_mips = 0.0, seconds_calibrate = 0.0;
  float uncalibrated_error = 0.f;  // relative RMS at the calibration points before scaling
};

struct VxgiResult {
  std::vector<VxgiClipmap> clipmaps;  // [0] finest
  std::array<float, 3> sky{0.f, 0.f, 0.f};  // cd/m^2, for cones leaving the volume
  std::string settings_json;
  VxgiStats stats;
};

}  // namespace gibake
