// Clipmaps on the bake side: a finer clipmap is the scene voxelized at its voxel size,
// cut to the coarsest clipmap's voxel counts around the centre, then lit, distanced and mipped
// like the coarsest (one clipmap = one volume of the file, docs/FORMAT.md).
#include <algorithm>
#include <cmath>

#include "bake/vxgi/vxgi.h"
#include "bake/vxgi/vxgi_mips.h"
#include "gibake/loader.hpp"
#include "io/timer.h"

namespace gibake {

VoxelGrid vxgi_crop_grid(const VoxelGrid& full, const std::array<float, 3>& center, const std::array<int32_t, 3>& dims) {
  VoxelGrid out;
  out.voxel_size = full.voxel_size;
  out.dims = dims;
  int32_t off[3];
  for (int a = 0; a < 3; ++a) {
    const double h = double(full.voxel_size);
    const double want = double(center[size_t(a)]) - 0.5 * double(dims[size_t(a)]) * h;
    off[a] = int32_t(std::llround((want - double(full.origin[size_t(a)])) / h));
    out.origin[size_t(a)] = float(double(full.origin[size_t(a)]) + double(off[a]) * h);
  }
  const size_t cells = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
  out.space.assign(cells, uint8_t(VoxelSpace::Exterior));
  for (int32_t z = 0; z < dims[2]; ++z)
    for (int32_t y = 0; y < dims[1]; ++y)
      for (int32_t x = 0; x < dims[0]; ++x) {
        const int32_t fx = x + off[0], fy = y + off[1], fz = z + off[2];
        if (fx < 0 || fy < 0 || fz < 0 || fx >= full.dims[0] || fy >= full.dims[1] || fz >= full.dims[2]) continue;
        out.space[size_t(out.linear(x, y, z))] = full.space[size_t(full.linear(fx, fy, fz))];
      }
  // Both orders are z, then y, then x: the kept voxels stay sorted by the cut grid's linear index.
  for (const SurfaceVoxel& sv : full.surface) {
    SurfaceVoxel c = sv;
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      c.ijk[a] = sv.ijk[a] - off[a];
      inside = inside && c.ijk[a] >= 0 && c.ijk[a] < dims[size_t(a)];
    }
    if (inside) out.surface.push_back(c);
  }
  return out;
}

void vxgi_cap_free_distance(std::vector<float>& free, const std::array<int32_t, 3>& d, float voxel_size) {
  for (int32_t z = 0; z < d[2]; ++z)
    for (int32_t y = 0; y < d[1]; ++y)
      for (int32_t x = 0; x < d[0]; ++x) {
        // Whole voxels between this one and the border: geometry beyond is at least that far.
        const int32_t n = std::min({x, y, z, d[0] - 1 - x, d[1] - 1 - y, d[2] - 1 - z});
        float& v = free[size_t(x) + size_t(d[0]) * (size_t(y) + size_t(d[1]) * size_t(z))];
        v = std::min(v, float(n) * voxel_size);
      }
}

void vxgi_precompute_cones(VxgiClipmap& clip) {
  const std::array<loader::Vec3, 16>& dirs = loader::precomputed_cone_directions();
  for (size_t l = 0; l < clip.levels.size(); ++l) {
    const std::array<int32_t, 3> d = vxgi_level_dims(clip.dims, int(l));
    const size_t cells = size_t(d[0]) * size_t(d[1]) * size_t(d[2]);
    std::vector<float>& level = clip.levels[l];
    level.resize(size_t(kVxgiFaces + 16) * cells * 4, 0.f);
    for (size_t i = 0; i < 16; ++i) {
      float* out = level.data() + (size_t(kVxgiFaces) + i) * cells * 4;
      for (int a = 0; a < 3; ++a) {
        const float w = dirs[i][size_t(a)] * dirs[i][size_t(a)];
        const size_t face = size_t(2 * a + (dirs[i][size_t(a)] < 0.f ? 0 : 1));  // as VxgiVolume::sample_cone
        const float* in = level.data() + face * cells * 4;
        for (size_t k = 0; k < cells * 4; ++k) out[k] += w * in[k];
      }
    }
  }
  clip.faces = kVxgiFaces + 16;
}

Status vxgi_bake_clipmap(const VoxelGrid& grid, bool cut, uint32_t stream, const PreparedScene& prepared,
                         const std::vector<kernels::ShadeLight>& lights, const Sky& sky, const VxgiSettings& s,
                         const Context& ctx, VxgiClipmap& clip, VxgiStats& stats) {
  clip = VxgiClipmap();
  clip.grid_min = grid.origin;
  clip.voxel_size = grid.voxel_size;
  clip.dims = grid.dims;
  auto t0 = Clock::now();
  std::vector<float> level0;
  GIBAKE_TRY(vxgi_radiance(grid, prepared, lights, sky, s, ctx, level0, stats, stream));
  stats.seconds_radiance += seconds_since(t0);
  t0 = Clock::now();
  if (s.sdf) {
    clip.sdf = vxgi_free_distance(level0, clip.dims, clip.voxel_size);
    if (cut) vxgi_cap_free_distance(clip.sdf, clip.dims, clip.voxel_size);
  }
  clip.levels.push_back(std::move(level0));
  const int levels = vxgi_full_levels(clip.dims);
  for (int l = 1; l < levels; ++l)
    clip.levels.push_back(vxgi_downsample(clip.levels.back(), vxgi_level_dims(clip.dims, l - 1)));
  if (s.precompute_cones) vxgi_precompute_cones(clip);  // after the mips: they read the six faces only
  stats.seconds_mips += seconds_since(t0);
  return Status::ok();
}

}  // namespace gibake
