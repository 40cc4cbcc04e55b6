#include "bake/voxel/leak_audit.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/run/arena.h"
#include "bake/scene/emitters.h"

namespace gibake {
namespace {

using kernels::float3;

// A walk along +axis from empty voxel `a` through wall voxels to empty voxel `b` (linear indices).
struct Crossing {
  int64_t a = 0, b = 0;
  int axis = 0;
  int32_t wall = 0;  // voxels between a and b
};

bool is_empty(const VoxelGrid& g, int64_t i) { return g.space[size_t(i)] != uint8_t(VoxelSpace::Surface); }

int64_t axis_stride(const VoxelGrid& g, int axis) {
  return axis == 0 ? 1 : axis == 1 ? int64_t(g.dims[0]) : int64_t(g.dims[0]) * g.dims[1];
}

// Walls on one line: from an empty voxel with `open` empty voxels behind it, through fewer than
// `max_wall` voxels of which the first is a surface, to `open` empty voxels (room for a probe).
void line_crossings(const VoxelGrid& g, int axis, int64_t start, int32_t open, int32_t max_wall,
                    std::vector<Crossing>& out) {
  const int64_t stride = axis_stride(g, axis);
  const int32_t n = g.dims[axis];
  auto empty_at = [&](int32_t i) { return is_empty(g, start + stride * i); };
  // `open` empty voxels from `from`; twice that in closed (Interior) space, so that the hollow
  // inside of a closed wall or object is crossed as part of it and a closed room still counts.
  auto open_run = [&](int32_t from, int32_t step) {
    const bool closed = g.space[size_t(start + stride * from)] == uint8_t(VoxelSpace::Interior);
    const int32_t depth = closed ? 2 * open : open;
    for (int32_t k = 0; k < depth; ++k) {
      const int32_t i = from + step * k;
      if (i < 0 || i >= n || !empty_at(i)) return false;
    }
    return true;
  };
  for (int32_t i = 0; i + 1 < n; ++i) {
    if (!empty_at(i) || empty_at(i + 1) || !open_run(i, -1)) continue;
    for (int32_t j = i + 2; j < n && j - i - 1 < max_wall; ++j) {
      if (!empty_at(j)) continue;
      if (open_run(j, +1)) {
        out.push_back({start + stride * i, start + stride * j, axis, j - i - 1});
        break;
      }
    }
  }
}

std::array<int32_t, 3> coords(const VoxelGrid& g, int64_t i) {
  const int64_t x = i % g.dims[0], yz = i / g.dims[0];
  return {int32_t(x), int32_t(yz % g.dims[1]), int32_t(yz / g.dims[1])};
}

float3 centre(const VoxelGrid& g, int64_t i) {
  const auto c = coords(g, i);
  const auto p = g.voxel_center(c[0], c[1], c[2]);
  return {p[0], p[1], p[2]};
}

// Direct visibility of any light, or of sample points on emissive triangles, from p.
struct LitTest {
  const PreparedScene& prepared;
  const std::vector<kernels::ShadeLight>& lights;
  std::vector<float3> emitter_points;

  bool operator()(const float3& p, uint64_t& rays) const {
    for (const kernels::ShadeLight& light : lights) {
      kernels::LightSample s;
      if (!kernels::sample_light(light, p, s)) continue;
      ++rays;
      if (!prepared.occluded(p, s.to_light, 0.f, s.distance)) return true;
    }
    for (const float3& q : emitter_points) {
      const float3 d = q - p;
      const float dist = kernels::length(d);
      if (!(dist > 0.f)) return true;
      ++rays;
      if (!prepared.occluded(p, d * (1.f / dist), 0.f, dist * 0.999f)) return true;
    }
    return false;
  }
};

std::vector<float3> emitter_points(const Scene& scene, int samples) {
  std::vector<float3> points;
  const EmitterTable table(scene);
  if (table.empty()) return points;
  for (int i = 0; i < samples; ++i) {  // stratified in the triangle choice, golden-ratio points on it
    const float u1 = std::fmod(0.6180340f * float(i) + 0.25f, 1.f), u2 = std::fmod(0.4142136f * float(i) + 0.5f, 1.f);
    points.push_back(table.sample((float(i) + 0.5f) / float(samples), u1, u2).position);
  }
  return points;
}

std::vector<Crossing> find_crossings(const VoxelGrid& g, int32_t open, int32_t max_wall, tbb::task_arena& arena) {
  std::vector<Crossing> all;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int64_t lines = int64_t(g.dims[u]) * g.dims[v];
    std::vector<std::vector<Crossing>> per_line(static_cast<size_t>(lines));
    arena.execute([&] {
      tbb::parallel_for(int64_t(0), lines, [&](int64_t l) {
        int32_t ijk[3];
        ijk[axis] = 0;
        ijk[u] = int32_t(l % g.dims[u]);
        ijk[v] = int32_t(l / g.dims[u]);
        line_crossings(g, axis, g.linear(ijk[0], ijk[1], ijk[2]), open, max_wall, per_line[size_t(l)]);
      });
    });
    for (auto& c : per_line) all.insert(all.end(), c.begin(), c.end());
  }
  return all;
}

// Lit state of every voxel a crossing starts or ends at, in parallel (a pure function per voxel).
void test_ends(const VoxelGrid& g, const std::vector<Crossing>& crossings, const LitTest& lit, tbb::task_arena& arena,
               std::vector<int64_t>& voxels, std::vector<uint8_t>& state, uint64_t& rays) {
  for (const Crossing& c : crossings) {
    voxels.push_back(c.a);
    voxels.push_back(c.b);
  }
  std::sort(voxels.begin(), voxels.end());
  voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
  state.assign(voxels.size(), 0);
  std::vector<uint64_t> ray_counts(voxels.size(), 0);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), voxels.size(),
                      [&](size_t i) { state[i] = lit(centre(g, voxels[i]), ray_counts[i]) ? 1 : 0; });
  });
  for (uint64_t r : ray_counts) rays += r;
}

// 26-connected regions of marked wall voxels, in voxel order; largest first.
void collect_regions(const VoxelGrid& g, const std::vector<Crossing>& crossings, const std::vector<uint32_t>& mark,
                     const std::vector<uint8_t>& lit_a, LeakAudit& out, size_t max_regions) {
  std::vector<uint8_t> seen(mark.size(), 0);
  std::vector<LeakRegion> regions;
  std::vector<int64_t> stack;
  const float h = g.voxel_size;
  for (int64_t start = 0; start < int64_t(mark.size()); ++start) {
    if (!mark[size_t(start)] || seen[size_t(start)]) continue;
    LeakRegion r;
    const Crossing& first = crossings[mark[size_t(start)] - 1];
    r.axis = first.axis;
    const float3 pa = centre(g, first.a), pb = centre(g, first.b);
    const bool a_lit = lit_a[mark[size_t(start)] - 1] != 0;
    r.lit_point = a_lit ? std::array<float, 3>{pa.x, pa.y, pa.z} : std::array<float, 3>{pb.x, pb.y, pb.z};
    r.dark_point = a_lit ? std::array<float, 3>{pb.x, pb.y, pb.z} : std::array<float, 3>{pa.x, pa.y, pa.z};
    r.dark_enclosed = g.space[size_t(a_lit ? first.b : first.a)] == uint8_t(VoxelSpace::Interior);
    std::array<int32_t, 3> lo = coords(g, start), hi = lo;
    stack.assign(1, start);
    seen[size_t(start)] = 1;
    while (!stack.empty()) {
      const int64_t i = stack.back();
      stack.pop_back();
      ++r.voxels;
      r.thickness = std::max(r.thickness, float(crossings[mark[size_t(i)] - 1].wall) * h);
      const auto c = coords(g, i);
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int32_t x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
            if (x < 0 || y < 0 || z < 0 || x >= g.dims[0] || y >= g.dims[1] || z >= g.dims[2]) continue;
            const int64_t j = g.linear(x, y, z);
            if (mark[size_t(j)] && !seen[size_t(j)]) seen[size_t(j)] = 1, stack.push_back(j);
          }
    }
    for (int a = 0; a < 3; ++a) {
      r.min[a] = g.origin[a] + float(lo[a]) * h;
      r.max[a] = g.origin[a] + float(hi[a] + 1) * h;
    }
    regions.push_back(r);
  }
  std::stable_sort(regions.begin(), regions.end(),
                   [](const LeakRegion& x, const LeakRegion& y) { return x.voxels > y.voxels; });
  out.regions_total = regions.size();
  if (regions.size() > max_regions) regions.resize(max_regions);
  out.regions = std::move(regions);
}

}  // namespace

Status audit_leaks(const VoxelGrid& grid, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                   const LeakAuditSettings& settings, const Context& ctx, LeakAudit& out) {
  out = LeakAudit{};
  out.probe_spacing = settings.probe_spacing;
  if (!(settings.probe_spacing > 0.f) || !std::isfinite(settings.probe_spacing))
    return Status::error(ExitCode::BadArguments, "", "leak audit", "probe spacing must be a positive number of metres");
  if (grid.empty() || !(grid.voxel_size > 0.f)) return Status::ok();
  const float h = grid.voxel_size;
  // Walls crossed in fewer voxels than the spacing (the voxelized wall over-covers the true one),
  // with open space at least one spacing deep on both sides: room for a probe cell. Hollow walls
  // (closed shapes with space inside) are crossed whole, since their inside is shallower.
  const int32_t max_wall = std::max<int32_t>(1, int32_t(std::ceil(settings.probe_spacing / h)));
  const int32_t open = max_wall;
  auto arena = make_arena(ctx);
  const std::vector<Crossing> crossings = find_crossings(grid, open, max_wall, *arena);
  out.thin_wall_crossings = crossings.size();
  const LitTest lit{prepared, lights, emitter_points(prepared.scene(), settings.emitter_samples)};
  std::vector<int64_t> voxels;
  std::vector<uint8_t> state;
  test_ends(grid, crossings, lit, *arena, voxels, state, out.rays);
  auto lit_at = [&](int64_t i) { return state[size_t(std::lower_bound(voxels.begin(), voxels.end(), i) - voxels.begin())]; };
  std::vector<uint32_t> mark(grid.space.size(), 0);
  std::vector<uint8_t> lit_a(crossings.size(), 0);
  for (size_t c = 0; c < crossings.size(); ++c) {
    const Crossing& x = crossings[c];
    lit_a[c] = lit_at(x.a);
    if (lit_a[c] == lit_at(x.b)) continue;
    const int64_t stride = axis_stride(grid, x.axis);
    for (int64_t i = x.a + stride; i < x.b; i += stride)
      if (!mark[size_t(i)]) mark[size_t(i)] = uint32_t(c + 1), ++out.leak_voxels;
  }
  collect_regions(grid, crossings, mark, lit_a, out, settings.max_regions);
  return Status::ok();
}

std::string describe_leak(const LeakRegion& r, float probe_spacing) {
  static const char* const kAxis[3] = {"x", "y", "z"};
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "leak risk: wall at x %.2f..%.2f m, y %.2f..%.2f m, z %.2f..%.2f m (at most %.3f m thick along %s, "
                "%llu voxels; probe spacing %.3g m) separates lit space at (%.2f, %.2f, %.2f) from unlit %s at "
                "(%.2f, %.2f, %.2f); probes on both sides blend across it (thicken the wall or place probes closer)",
                double(r.min[0]), double(r.max[0]), double(r.min[1]), double(r.max[1]), double(r.min[2]),
                double(r.max[2]), double(r.thickness), kAxis[r.axis], static_cast<unsigned long long>(r.voxels),
                double(probe_spacing), double(r.lit_point[0]), double(r.lit_point[1]), double(r.lit_point[2]),
                r.dark_enclosed ? "closed space (a closed room, or the inside of a closed shape)" : "space",
                double(r.dark_point[0]), double(r.dark_point[1]), double(r.dark_point[2]));
  return buf;
}

}  // namespace gibake
