// Signed distance field over the voxel grid (VoxelGrid::sdf), at voxel centres, in metres.
//
// Magnitude:
//   * next to the triangles: OpenVDB's meshToUnsignedDistanceField on the same transform (its
//     voxel (i,j,k) is ours: centre at origin + (ijk + 0.5) * size). OpenVDB voxelizes every
//     triangle over the voxels within sqrt(3)/2 voxel of it with the exact point-triangle distance,
//     so its values up to sqrt(3)/2 voxel are exact; beyond that its band grows by taking each
//     voxel's neighbours' closest triangles, which can run high by a large part of a voxel on finely
//     tessellated meshes, so those values are not used. Unsigned, because game meshes are
//     rarely watertight and OpenVDB's signed variant needs a closed surface;
//   * further out: an exact Euclidean distance transform to the nearest surface-voxel centre
//     (Felzenszwalb & Huttenlocher's separable lower envelope of parabolas, one pass per axis,
//     every line independent: deterministic and parallel), minus sqrt(3)/2 voxel (every surface
//     point lies within that of some surface-voxel centre), and at least sqrt(3)/2 voxel (no
//     triangle is nearer, or OpenVDB would have voxelized it over this voxel). This is a lower
//     bound of the true distance, so sphere tracing never steps through a surface, and it is
//     within sqrt(3) voxels of it. A jump flood is a GPU approximation of the same
//     transform; on the CPU the exact one costs about as much.
// Sign: negative in Interior voxels; a Surface voxel is negative when the empty voxels nearest to
// it (within 2 voxels) are mostly Interior, i.e. its centre is on the enclosed side.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bake/voxel/voxel_internal.h"
#include "io/vdb/vdb_module.h"

namespace gibake::voxel {
namespace {

constexpr float kFar = 1e20f;
constexpr float kHalfDiagonal = 0.8660254f;  // sqrt(3)/2 voxel: OpenVDB's exact zone

// 1D squared distance transform of f (length n) into d (entries >= kFar are empty); v, z are
// scratch (n and n+1 entries).
void edt_1d(const double* f, int n, double* d, int* v, double* z) {
  const double inf = std::numeric_limits<double>::infinity();
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kFar) continue;
    double s = -inf;
    while (k >= 0) {
      const int p = v[k];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * double(q - p));
      if (s > z[k]) break;
      --k;
    }
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -inf;
    } else {
      ++k;
      v[k] = q;
      z[k] = s;
    }
    z[k + 1] = inf;
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) d[q] = kFar;
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < double(q)) ++j;
    const double dq = double(q - v[j]);
    d[q] = dq * dq + f[v[j]];
  }
}

// In-place squared EDT of `g` (dims X,Y,Z) along `axis`, all lines in parallel.
void edt_axis(std::vector<float>& g, const std::array<int32_t, 3>& dims, int axis, tbb::task_arena& arena) {
  const int64_t stride[3] = {1, dims[0], int64_t(dims[0]) * dims[1]};
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  const int n = dims[axis];
  const int64_t lines = int64_t(dims[a1]) * dims[a2];
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, lines, 64), [&](const tbb::blocked_range<int64_t>& r) {
      std::vector<double> f(n), d(n), z(n + 1);
      std::vector<int> v(n);
      for (int64_t l = r.begin(); l != r.end(); ++l) {
        const int64_t base = (l % dims[a1]) * stride[a1] + (l / dims[a1]) * stride[a2];
        for (int q = 0; q < n; ++q) f[q] = g[size_t(base + q * stride[axis])];
        edt_1d(f.data(), n, d.data(), v.data(), z.data());
        for (int q = 0; q < n; ++q) g[size_t(base + q * stride[axis])] = float(std::min(d[q], double(kFar)));
      }
    });
  });
}

// The query for OpenVDB's unsigned distances next to the triangles (finite ones only).
vdb::NearDistanceQuery near_query(const Scene& scene, const VoxelGrid& grid) {
  vdb::NearDistanceQuery q;
  q.positions = scene.positions.data();
  q.vertex_count = scene.vertex_count();
  q.triangles.reserve(scene.triangle_count() * 3);
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    const uint32_t* ix = &scene.indices[t * 3];
    bool finite = true;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(scene.positions[size_t(ix[k]) * 3 + a]);
    if (finite) q.triangles.insert(q.triangles.end(), ix, ix + 3);
  }
  q.voxel_size = grid.voxel_size;
  q.origin = grid.origin;
  q.dims = grid.dims;
  return q;
}

// Neighbour offsets within 2 voxels, nearest first.
std::vector<std::array<int32_t, 4>> shell_offsets() {
  std::vector<std::array<int32_t, 4>> o;
  for (int32_t z = -2; z <= 2; ++z)
    for (int32_t y = -2; y <= 2; ++y)
      for (int32_t x = -2; x <= 2; ++x)
        if (x || y || z) o.push_back({x, y, z, x * x + y * y + z * z});
  std::stable_sort(o.begin(), o.end(), [](const auto& a, const auto& b) { return a[3] < b[3]; });
  return o;
}

// A surface voxel's centre is taken to be inside when the nearest empty voxels (within 2 voxels)
// are more often Interior than Exterior: the centre lies on the side of the surface whose free
// space is closer. No empty voxel near, or a tie: outside.
bool surface_is_inside(const VoxelGrid& g, const std::vector<std::array<int32_t, 4>>& shell, int32_t x, int32_t y,
                       int32_t z) {
  int interior = 0, exterior = 0, found_d2 = -1;
  for (const auto& o : shell) {
    if (found_d2 >= 0 && o[3] > found_d2) break;
    const int32_t p[3] = {x + o[0], y + o[1], z + o[2]};
    if (p[0] < 0 || p[1] < 0 || p[2] < 0 || p[0] >= g.dims[0] || p[1] >= g.dims[1] || p[2] >= g.dims[2]) continue;
    const uint8_t s = g.space[size_t(g.linear(p[0], p[1], p[2]))];
    if (s == uint8_t(VoxelSpace::Surface)) continue;
    found_d2 = o[3];
    (s == uint8_t(VoxelSpace::Interior) ? interior : exterior) += 1;
  }
  return interior > exterior;
}

}  // namespace

double sdf_bytes_estimate(double voxels, double surface) {
  // Dense float result and OpenVDB's band copied out densely; OpenVDB's grids (distance and
  // closest-triangle index, about 3 voxels per surface voxel, with leaf overhead); the mesh copy is
  // counted with the triangles.
  return voxels * 8.0 + surface * 3.0 * 16.0;
}

Status compute_sdf(const Scene& scene, tbb::task_arena& arena, VoxelGrid& g) {
  std::vector<float> near;  // OpenVDB's band: its distance where it voxelized a triangle, else +inf
  Status near_status;
  arena.execute(
      [&] { near_status = vdb::near_distances(near_query(scene, g), near, scene.source_path, "voxelize: sdf"); });
  GIBAKE_TRY(near_status);
  const size_t n = g.space.size();
  std::vector<float>& d = g.sdf;
  d.assign(n, kFar);
  for (const SurfaceVoxel& s : g.surface) d[size_t(g.linear(s.ijk[0], s.ijk[1], s.ijk[2]))] = 0.f;
  for (int axis = 0; axis < 3; ++axis) edt_axis(d, g.dims, axis, arena);
  const float h = g.voxel_size, half_diag = kHalfDiagonal * h;
  const int64_t X = g.dims[0], Y = g.dims[1];
  const std::vector<std::array<int32_t, 4>> shell = shell_offsets();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, g.dims[2], 1), [&](const tbb::blocked_range<int32_t>& r) {
      for (int32_t z = r.begin(); z != r.end(); ++z)
        for (int32_t y = 0; y < Y; ++y)
          for (int32_t x = 0; x < X; ++x) {
            const size_t i = size_t(g.linear(x, y, z));
            float mag = near[i];
            if (mag > half_diag) mag = std::max(half_diag, std::sqrt(d[i]) * h - half_diag);
            const uint8_t s = g.space[i];
            const bool inside = s == uint8_t(VoxelSpace::Interior) ||
                                (s == uint8_t(VoxelSpace::Surface) && surface_is_inside(g, shell, x, y, z));
            d[i] = inside ? -mag : mag;
          }
    });
  });
  return Status::ok();
}

}  // namespace gibake::voxel
