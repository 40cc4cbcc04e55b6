#include "bake/vxgi/vxgi.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "bake/run/arena.h"
#include "bake/scene/emitters.h"
#include "bake/trace/path_gather.h"
#include "bake/voxel/voxelize.h"
#include "bake/vxgi/vxgi_mips.h"
#include "io/size_text.h"
#include "io/timer.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"

namespace gibake {
using kernels::float3;

namespace {


// voxel_size 0: from the resolution (the coarsest clipmap).
VoxelSettings voxel_settings_for(const VxgiSettings& s, float voxel_size = 0.f, std::array<int32_t, 3> low_extra = {}) {
  VoxelSettings v;
  v.low_extra = low_extra;
  v.resolution = s.resolution;
  v.voxel_size = voxel_size;
  v.sdf = false;  // the VDB-grade level set is not needed: vxgi_free_distance is enough for cone steps
  v.blend_cutoff = s.blend_cutoff;
  v.max_bytes = s.max_bytes;
  return v;
}

}  // namespace

std::vector<uint8_t> vxgi_solid_interior(const VoxelGrid& g) {
  const size_t cells = g.space.size();
  std::vector<int32_t> comp(cells, -1);
  std::vector<double> vote;
  std::vector<size_t> stack;
  const int32_t step[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (size_t seed = 0; seed < cells; ++seed) {
    if (g.space[seed] != uint8_t(VoxelSpace::Interior) || comp[seed] >= 0) continue;
    const int32_t id = int32_t(vote.size());
    vote.push_back(0.0);
    comp[seed] = id;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const size_t c = stack.back();
      stack.pop_back();
      const int32_t p[3] = {int32_t(c % size_t(g.dims[0])), int32_t((c / size_t(g.dims[0])) % size_t(g.dims[1])),
                            int32_t(c / (size_t(g.dims[0]) * size_t(g.dims[1])))};
      for (const auto& d : step) {
        const int32_t q[3] = {p[0] + d[0], p[1] + d[1], p[2] + d[2]};
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= g.dims[0] || q[1] >= g.dims[1] || q[2] >= g.dims[2]) continue;
        const size_t n = size_t(g.linear(q[0], q[1], q[2]));
        if (g.space[n] == uint8_t(VoxelSpace::Interior)) {
          if (comp[n] < 0) {
            comp[n] = id;
            stack.push_back(n);
          }
        } else if (const SurfaceVoxel* sv = g.find_surface(q[0], q[1], q[2])) {
          // A solid's surface faces away from its inside; a closed room's walls face into it.
          vote[size_t(id)] += sv->normal[0] * float(d[0]) + sv->normal[1] * float(d[1]) + sv->normal[2] * float(d[2]);
        }
      }
    }
  }
  std::vector<uint8_t> solid(cells, 0);
  for (size_t c = 0; c < cells; ++c) solid[c] = comp[c] >= 0 && vote[size_t(comp[c])] > 0.0;
  return solid;
}

Status validate_vxgi_settings(const VxgiSettings& s) {
  auto bad = [](const std::string& where, const std::string& what) {
    return Status::error(ExitCode::BadArguments, "", where, what);
  };
  const auto got = [](int64_t v) { return ", got " + std::to_string(v); };
  if (s.resolution < 4 || s.resolution > kMaxVxgiResolution)
    return bad("--vxgi-res", "must be between 4 and " + std::to_string(kMaxVxgiResolution) + got(s.resolution));
  if (s.bounces < 0 || s.bounces > 64) return bad("--vxgi-bounces", "must be between 0 and 64" + got(s.bounces));
  if (s.rays < 1 || s.rays > 65536) return bad("--vxgi-rays", "must be between 1 and 65536" + got(s.rays));
  if (s.calibration_points > 65536) return bad("--vxgi-calibrate", "at most 65536 points" + got(s.calibration_points));
  if (s.calibration_points && (s.calibration_rays < 1 || s.calibration_rays > 65536))
    return bad("--vxgi-calibrate", "rays per point must be between 1 and 65536" + got(s.calibration_rays));
  if (s.clipmaps < 1 || s.clipmaps > 8) return bad("--vxgi-clipmaps", "must be between 1 and 8" + got(s.clipmaps));
  if (s.align_levels < 0 || s.align_levels > 6)
    return bad("--vxgi-align-walls", "must be between 0 and 6" + got(s.align_levels));
  for (float c : s.center)
    if (s.has_center && !std::isfinite(c)) return bad("--vxgi-center", "must be three finite numbers of metres");
  return Status::ok();
}

std::string vxgi_settings_json(const VxgiSettings& s) {
  nlohmann::json j{{"resolution", s.resolution}, {"bounces", s.bounces}, {"rays", s.rays},
                   {"seed", s.seed},             {"sdf", s.sdf},         {"blend_cutoff", s.blend_cutoff},
                   {"calibration_points", s.calibration_points}, {"calibration_rays", s.calibration_rays}};
  if (s.clipmaps > 1) j["clipmaps"] = s.clipmaps;
  if (s.precompute_cones) j["precompute_cones"] = true;
  if (s.split_sides) {  // only when asked: default bakes keep their bytes
    j["split_sides"] = true;
    j["align_levels"] = s.align_levels;
  }  // only when asked: single-volume bakes keep their bytes
  if (s.has_center) j["center"] = s.center;
  return j.dump();
}

namespace {

// Voxels added below the single volume's grid so that its thin walls' two layers stay in separate
// mip texels (vxgi_align.cpp); none without split sides or with clipmaps. Without `prepared` (the
// plan's estimate): the most it can be.
bool aligns(const VxgiSettings& s) { return s.split_sides && s.clipmaps == 1 && s.align_levels > 0; }

Status wall_shift(const Scene& scene, const PreparedScene* prepared, const std::vector<kernels::ShadeLight>& lights,
                  const VxgiSettings& s, std::array<int32_t, 3>& shift) {
  shift = {0, 0, 0};
  if (!aligns(s)) return Status::ok();
  if (!prepared) {
    shift.fill((1 << s.align_levels) - 1);
    return Status::ok();
  }
  VoxelGrid layout;
  uint64_t bytes = 0;
  VoxelSettings vs = voxel_settings_for(s);
  vs.max_bytes = ~uint64_t(0);
  GIBAKE_TRY(plan_voxel_grid(scene, vs, layout, bytes));
  shift = vxgi_wall_alignment(*prepared, lights, layout, s.align_levels);
  return Status::ok();
}

}  // namespace

Status plan_vxgi(const Scene& scene, const VxgiSettings& s, VoxelGrid& layout, uint64_t& estimated) {
  GIBAKE_TRY(validate_vxgi_settings(s));
  uint64_t voxel_bytes = 0;
  std::array<int32_t, 3> shift;
  GIBAKE_TRY(wall_shift(scene, nullptr, {}, s, shift));
  VoxelSettings vs = voxel_settings_for(s, 0.f, shift);
  vs.max_bytes = ~uint64_t(0);  // judged below, with the VXGI payload added
  GIBAKE_TRY(plan_voxel_grid(scene, vs, layout, voxel_bytes));
  const uint64_t cells = uint64_t(layout.dims[0]) * uint64_t(layout.dims[1]) * uint64_t(layout.dims[2]);
  // float RGBA per face (mips add at most 1/7), the f16 file payload, the free distance.
  const uint64_t faces = s.precompute_cones ? kVxgiFaces + 16 : kVxgiFaces;
  const uint64_t per_cell = faces * (16 + 8) * 8 / 7 + (s.sdf ? 8 : 0);
  if (s.clipmaps > 1) {  // the finest clipmap's voxelizer covers the whole scene at its voxel size
    VoxelGrid fine;
    uint64_t fine_bytes = 0;
    VoxelSettings fs = voxel_settings_for(s, std::ldexp(layout.voxel_size, 1 - s.clipmaps));
    fs.max_bytes = ~uint64_t(0);
    GIBAKE_TRY(plan_voxel_grid(scene, fs, fine, fine_bytes));
    voxel_bytes = std::max(voxel_bytes, fine_bytes);
  }
  estimated = voxel_bytes + cells * per_cell * uint64_t(s.clipmaps);
  for (int a = 0; a < 3; ++a)
    if (layout.dims[size_t(a)] > 4096)
      return Status::error(ExitCode::BadArguments, "", "--vxgi-res",
                           "the grid would be " + std::to_string(layout.dims[size_t(a)]) +
                               " voxels on one axis; the format allows 4096");
  // With clipmaps the finest one's voxelization of the whole scene is most of it: name their count.
  const std::string grids = s.clipmaps > 1 ? std::to_string(s.clipmaps) + " clipmaps of " : "a ";
  if (estimated > s.max_bytes)
    return Status::error(ExitCode::BadArguments, "", s.clipmaps > 1 ? "--vxgi-clipmaps" : "--vxgi-res",
                         grids + std::to_string(layout.dims[0]) + "x" + std::to_string(layout.dims[1]) + "x" +
                             std::to_string(layout.dims[2]) + " voxel GI grid" +
                             (s.clipmaps > 1 ? "s need" : " needs") + " about " + size_text(double(estimated)) +
                             ", more than the " + size_text(double(s.max_bytes)) +
                             " of --max-memory; lower --vxgi-res" + (s.clipmaps > 1 ? " or --vxgi-clipmaps" : "") +
                             ", or raise --max-memory");
  return Status::ok();
}

std::vector<float> vxgi_free_distance(const std::vector<float>& level0, const std::array<int32_t, 3>& d,
                                      float voxel_size) {
  const size_t cells = size_t(d[0]) * size_t(d[1]) * size_t(d[2]);
  constexpr float kFar = 1e9f;
  std::vector<float> dist(cells, kFar);
  for (size_t c = 0; c < cells; ++c)
    for (int f = 0; f < kVxgiFaces; ++f)
      if (level0[(size_t(f) * cells + c) * 4 + 3] > 0.f) dist[c] = 0.f;
  auto idx = [&](int32_t x, int32_t y, int32_t z) { return size_t(x) + size_t(d[0]) * (size_t(y) + size_t(d[1]) * size_t(z)); };
  // Two-pass 26-neighbour chamfer (weights 1, sqrt 2, sqrt 3): forward then backward raster order.
  for (int pass = 0; pass < 2; ++pass) {
    const int st = pass == 0 ? 1 : -1;
    for (int32_t zi = 0; zi < d[2]; ++zi)
      for (int32_t yi = 0; yi < d[1]; ++yi)
        for (int32_t xi = 0; xi < d[0]; ++xi) {
          const int32_t x = pass == 0 ? xi : d[0] - 1 - xi, y = pass == 0 ? yi : d[1] - 1 - yi,
                        z = pass == 0 ? zi : d[2] - 1 - zi;
          float best = dist[idx(x, y, z)];
          for (int dz = -1; dz <= 0; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;  // only voxels already visited
                const int32_t nx = x + st * dx, ny = y + st * dy, nz = z + st * dz;
                if (nx < 0 || ny < 0 || nz < 0 || nx >= d[0] || ny >= d[1] || nz >= d[2]) continue;
                const float w = std::sqrt(float(dx * dx + dy * dy + dz * dz));
                best = std::min(best, dist[idx(nx, ny, nz)] + w);
              }
          dist[idx(x, y, z)] = best;
        }
  }
  for (float& v : dist) v = v >= kFar ? 1e6f * voxel_size : std::max(0.f, v / 1.15f - 2.f) * voxel_size;
  return dist;
}

namespace {

// A centre outside the coarsest clipmap's box (the scene's) leaves every finer clipmap empty, and
// one far beyond it would not fit the voxel indices: refused, with the box it must lie in.
Status check_center_inside(const VxgiSettings& s, const VoxelGrid& layout) {
  if (!s.has_center || s.clipmaps < 2) return Status::ok();
  bool inside = true;
  float hi[3];
  for (int a = 0; a < 3; ++a) {
    hi[a] = layout.origin[size_t(a)] + float(layout.dims[size_t(a)]) * layout.voxel_size;
    inside = inside && s.center[size_t(a)] >= layout.origin[size_t(a)] && s.center[size_t(a)] <= hi[a];
  }
  if (inside) return Status::ok();
  char text[256];
  std::snprintf(text, sizeof text,
                "%g,%g,%g lies outside the scene's voxel box (%g,%g,%g to %g,%g,%g): the finer clipmaps would hold "
                "nothing; give a point within it",
                double(s.center[0]), double(s.center[1]), double(s.center[2]), double(layout.origin[0]),
                double(layout.origin[1]), double(layout.origin[2]), double(hi[0]), double(hi[1]), double(hi[2]));
  return Status::error(ExitCode::BadArguments, "", "--vxgi-center", text);
}

}  // namespace

Status bake_vxgi(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                 const Sky& sky, const VxgiSettings& s, const Context& ctx, VxgiResult& out) {
  VoxelGrid layout;
  uint64_t estimate = 0;
  GIBAKE_TRY(plan_vxgi(scene, s, layout, estimate));
  std::array<int32_t, 3> shift;
  GIBAKE_TRY(wall_shift(scene, &prepared, lights, s, shift));
  if (aligns(s)) {  // the layout of the grid as moved (the plan's estimate allowed for the most)
    uint64_t bytes = 0;
    VoxelSettings vs = voxel_settings_for(s, 0.f, shift);
    vs.max_bytes = ~uint64_t(0);
    GIBAKE_TRY(plan_voxel_grid(scene, vs, layout, bytes));
  }
  ctx.note("vxgi: " + (s.clipmaps > 1 ? std::to_string(s.clipmaps) + " clipmaps of " : std::string()) +
           std::to_string(layout.dims[0]) + "x" + std::to_string(layout.dims[1]) + "x" +
           std::to_string(layout.dims[2]) + " voxels of " + std::to_string(layout.voxel_size) + " m" +
           (s.clipmaps > 1 ? " (the coarsest)" : "") + ", about " + size_text(double(estimate)) + " of memory");
  out = VxgiResult();
  out.stats.estimated_bytes = estimate;
  out.settings_json = vxgi_settings_json(s);
  out.sky = {sky.constant.x * sky.scale, sky.constant.y * sky.scale, sky.constant.z * sky.scale};
  if (sky.width > 0) ctx.warning("vxgi: cones that leave the volume see black, not the --sky-hdr map");
  if (sky.width > 0) out.sky = {0.f, 0.f, 0.f};
  // Coarsest first: it covers the scene, and its grid places the finer ones and the calibration.
  out.clipmaps.resize(size_t(s.clipmaps));
  VoxelGrid coarse;
  std::array<float, 3> center = s.center;
  if (!s.has_center)
    for (int a = 0; a < 3; ++a) center[size_t(a)] = layout.origin[size_t(a)] + 0.5f * float(layout.dims[size_t(a)]) * layout.voxel_size;
  GIBAKE_TRY(check_center_inside(s, layout));
  for (int k = s.clipmaps - 1; k >= 0; --k) {
    const uint32_t from_outer = uint32_t(s.clipmaps - 1 - k);
    auto t0 = Clock::now();
    VoxelGrid grid;
    GIBAKE_TRY(voxelize(scene,
                        from_outer ? voxel_settings_for(s, std::ldexp(layout.voxel_size, -int(from_outer)))
                                   : voxel_settings_for(s, 0.f, shift),
                        ctx, grid));
    if (from_outer) grid = vxgi_crop_grid(grid, center, coarse.dims);
    out.stats.seconds_voxelize += seconds_since(t0);
    GIBAKE_TRY(vxgi_bake_clipmap(grid, from_outer != 0, from_outer, prepared, lights, sky, s, ctx,
                                 out.clipmaps[size_t(k)], out.stats));
    if (!from_outer) coarse = std::move(grid);
  }
  const auto t_fit = Clock::now();
  GIBAKE_TRY(vxgi_calibrate(coarse, prepared, lights, sky, s, ctx, out));
  out.stats.seconds_calibrate = seconds_since(t_fit);
  return Status::ok();
}

}  // namespace gibake
