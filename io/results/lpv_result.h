// Result of the LPV bake (bake/lpv/lpv.h), written by io/bake_file.cpp as lpv_cascade + lpv_sh
// sections (docs/FORMAT.md). Plain data.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace gibake {

// One cascade: cell (x,y,z) covers [grid_min + (x,y,z)*cell_size, +cell_size), index
// x + X*(y + Y*z). `sh` holds 12 floats per cell, [cell][channel R,G,B][coefficient 0..3]: the L1
// SH (project basis: Y00, Y1-1 (y), Y10 (z), Y11 (x)) of the radiant intensity I(w) in candela of
// the light in the cell, w the direction the light travels, accumulated over every iteration.
struct LpvCascade {
  std::array<float, 3> grid_min{0.f, 0.f, 0.f};  // metres
  float cell_size = 0.f;                         // metres
  std::array<int32_t, 3> dims{0, 0, 0};
  uint32_t iterations = 0;   // propagation steps accumulated
  bool occlusion = false;    // a geometry volume blocked propagation from the second step on
  std::vector<float> sh;     // cell_count() * 12
  size_t cell_count() const { return size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]); }
};

struct LpvStats {
  uint64_t vpl_rays = 0;            // rays traced from lights to find lit surfaces
  uint64_t vpls = 0;                // VPLs from lit surfaces
  uint64_t emissive_vpls = 0;       // VPLs sampled on emissive triangles
  uint64_t interior_vpls = 0;       // dropped: they leave into Interior voxels (closed space)
  std::array<double, 3> vpl_flux{0.0, 0.0, 0.0};  // lm, sum over all VPLs
  std::vector<uint64_t> injected;   // VPLs inside each cascade
  double seconds_vpls = 0.0, seconds_propagate = 0.0;
};

struct LpvResult {
  std::vector<LpvCascade> cascades;  // [0] is the finest (smallest) cascade
  std::string settings_json;         // lpv_settings_json()
  LpvStats stats;
};

}  // namespace gibake
