// Exterior flood fill (see voxel_internal.h): a scanline fill over x-runs. Each popped seed is
// grown to the whole run of unvisited voxels along x, the run is marked Exterior, and the four
// neighbouring rows (y +- 1, z +- 1) push one seed per unvisited run they share with it. The
// result is the unique set of empty voxels 6-connected to the border, whatever the visiting
// order, so it is deterministic; the stack holds runs, not voxels.
#include <cstdint>
#include <vector>

#include "bake/voxel/voxel_internal.h"

namespace gibake::voxel {
namespace {

constexpr uint8_t kExterior = uint8_t(VoxelSpace::Exterior);
constexpr uint8_t kInterior = uint8_t(VoxelSpace::Interior);

struct Seed {
  int32_t x, y, z;
};

struct Filler {
  int64_t X, Y, Z;
  uint8_t* s;
  std::vector<Seed> stack;

  uint8_t* row(int32_t y, int32_t z) const { return s + X * (int64_t(y) + Y * int64_t(z)); }

  // Pushes one seed per run of unvisited voxels of row (y, z) within [x0, x1].
  void scan(int32_t x0, int32_t x1, int32_t y, int32_t z) {
    if (y < 0 || z < 0 || y >= Y || z >= Z) return;
    const uint8_t* r = row(y, z);
    bool in_run = false;
    for (int32_t x = x0; x <= x1; ++x) {
      const bool open = r[x] == kUnvisited;
      if (open && !in_run) stack.push_back({x, y, z});
      in_run = open;
    }
  }

  void fill_from(int32_t x, int32_t y, int32_t z) {
    stack.push_back({x, y, z});
    while (!stack.empty()) {
      const Seed sd = stack.back();
      stack.pop_back();
      uint8_t* r = row(sd.y, sd.z);
      if (r[sd.x] != kUnvisited) continue;
      int32_t x0 = sd.x, x1 = sd.x;
      while (x0 > 0 && r[x0 - 1] == kUnvisited) --x0;
      while (x1 + 1 < X && r[x1 + 1] == kUnvisited) ++x1;
      for (int32_t i = x0; i <= x1; ++i) r[i] = kExterior;
      scan(x0, x1, sd.y - 1, sd.z);
      scan(x0, x1, sd.y + 1, sd.z);
      scan(x0, x1, sd.y, sd.z - 1);
      scan(x0, x1, sd.y, sd.z + 1);
    }
  }
};

}  // namespace

void flood_fill_exterior(const std::array<int32_t, 3>& dims, std::vector<uint8_t>& space) {
  Filler f{dims[0], dims[1], dims[2], space.data(), {}};
  const int32_t X = dims[0], Y = dims[1], Z = dims[2];
  // Seeds on all six faces of the grid.
  for (int32_t z = 0; z < Z; ++z)
    for (int32_t y = 0; y < Y; ++y) {
      const bool face = z == 0 || z == Z - 1 || y == 0 || y == Y - 1;
      uint8_t* r = f.row(y, z);
      if (face) {
        for (int32_t x = 0; x < X; ++x)
          if (r[x] == kUnvisited) f.fill_from(x, y, z);
      } else {
        if (r[0] == kUnvisited) f.fill_from(0, y, z);
        if (r[X - 1] == kUnvisited) f.fill_from(X - 1, y, z);
      }
    }
  for (uint8_t& v : space)
    if (v == kUnvisited) v = kInterior;
}

}  // namespace gibake::voxel
