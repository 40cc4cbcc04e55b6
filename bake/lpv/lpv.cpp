// LPV bake stage (bake/lpv/lpv.h): cascades, geometry volume, propagation, dense-grid export.
#include "bake/lpv/lpv.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

#include "bake/lpv/lpv_device.h"
#include "bake/run/arena.h"
#include "io/size_text.h"
#include "io/timer.h"

namespace gibake {
namespace {

using kernels::LpvCell;
using kernels::LpvGrid;

Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "lpv settings", what); }

// Runs f(z_begin, z_end) over z-planes, one plane per task: every cell is written by one task
// from read-only inputs, so the result does not depend on the thread count.
template <typename F>
void for_planes(tbb::task_arena& arena, int planes, F&& f) {
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, planes, 1),
                      [&](const tbb::blocked_range<int>& r) { f(r.begin(), r.end()); });
  });
}

uint64_t estimate_bytes(const LpvGrid& g) {
  const uint64_t cells = g.cells();
  // src, dst, accumulated (48 B each), flux scale (12 B), geometry corners (16 B), result (48 B).
  return cells * (48 * 4 + 12) + uint64_t(kernels::lpv_geometry_corners(g)) * 16;
}

}  // namespace

Status validate_lpv_settings(const LpvSettings& s) {
  const auto got = [](int v) { return ", got " + std::to_string(v); };
  if (s.resolution < 4 || s.resolution > 512) return bad("--lpv-res must be between 4 and 512" + got(s.resolution));
  if (s.iterations < 0 || s.iterations > kMaxLpvIterations)
    return bad("--lpv-iterations must be between 0 (auto) and " + std::to_string(kMaxLpvIterations) +
               got(s.iterations));
  if (s.cascades < 1 || s.cascades > 8) return bad("--lpv-cascades must be between 1 and 8" + got(s.cascades));
  if (s.vpl_samples > (1u << 26) || s.emissive_samples > (1u << 26))
    return bad("VPL sample counts must be at most 67108864");
  return Status::ok();
}

std::string lpv_settings_json(const LpvSettings& s, const BackendChoice* ran_on) {
  nlohmann::json j{{"resolution", s.resolution},
                   {"iterations", s.iterations},
                   {"cascades", s.cascades},
                   {"vpl_samples", s.vpl_samples},
                   {"emissive_samples", s.emissive_samples},
                   {"seed", s.seed},
                   {"occlusion", s.occlusion}};
  if (ran_on && ran_on->backend == Backend::Vulkan) {
    j["backend"] = backend_name(Backend::Vulkan);
    j["vulkan_device"] = ran_on->device.name;
    j["vulkan_driver"] = ran_on->device.driver;
  }
  return j.dump();
}

int lpv_default_iterations(const LpvGrid& grid) {
  const int64_t longest = std::max({grid.dims[0], grid.dims[1], grid.dims[2], int32_t(1)});
  return int(std::clamp<int64_t>(longest * longest / 4, 1, kMaxLpvIterations));
}

Status lpv_cascade_grids(const Bounds& bounds, const LpvSettings& s, std::vector<LpvGrid>& out) {
  GIBAKE_TRY(validate_lpv_settings(s));
  out.clear();
  float size[3], centre[3], longest = 0.f;
  for (int a = 0; a < 3; ++a) {
    size[a] = bounds.max[a] - bounds.min[a];
    centre[a] = 0.5f * (bounds.max[a] + bounds.min[a]);
    if (!std::isfinite(size[a]) || size[a] < 0.f || !std::isfinite(centre[a]))
      return Status::invalid("", "lpv", "scene bounds are empty or not finite");
    longest = std::max(longest, size[a]);
  }
  if (!(longest > 0.f)) longest = 1.f;
  const float outer_h = longest / float(s.resolution - 2);  // one cell of padding per side
  int32_t dims[3];
  for (int a = 0; a < 3; ++a) dims[a] = std::clamp(int32_t(std::ceil(size[a] / outer_h - 1e-3f)) + 2, 1, s.resolution);
  uint64_t bytes = 0;
  for (int k = 0; k < s.cascades; ++k) {
    LpvGrid g;
    const float h = outer_h / float(1 << (s.cascades - 1 - k));
    for (int a = 0; a < 3; ++a) {
      g.dims[a] = dims[a];
      g.origin_cell[a] = centre[a] - 0.5f * float(dims[a]) * h;
    }
    g.origin_cell[3] = h;
    bytes += estimate_bytes(g);
    out.push_back(g);
  }
  if (bytes > s.max_memory_bytes)
    return Status::error(ExitCode::BadArguments, "", "--lpv-res",
                         "the LPV would need about " + size_text(double(bytes)) + ", over the " +
                             size_text(double(s.max_memory_bytes)) +
                             " of --max-memory; lower --lpv-res or --lpv-cascades or raise --max-memory");
  return Status::ok();
}

void lpv_geometry_volume(const VoxelGrid& voxels, const LpvGrid& grid, std::vector<float>& out) {
  out.assign(kernels::lpv_geometry_corners(grid) * 4, 0.f);
  const float s = voxels.voxel_size, h = grid.cell_size();
  if (voxels.empty() || !(s > 0.f) || !(h > 0.f)) return;
  const int split = std::max(1, int(std::ceil(s / h - 1e-4f)));  // sub-voxels per axis
  const float sub = s / float(split);
  const float fraction_per_coverage = (sub * sub) / (h * h);
  for (const SurfaceVoxel& v : voxels.surface) {
    if (!(v.coverage > 0.f)) continue;
    const kernels::float3 n = kernels::load3(v.normal);
    for (int i = 0; i < split; ++i)
      for (int j = 0; j < split; ++j)
        for (int k = 0; k < split; ++k) {
          const int sub_ijk[3] = {i, j, k};
          int32_t corner[3];
          for (int a = 0; a < 3; ++a) {
            const float p = voxels.origin[a] + float(v.ijk[a]) * s + (float(sub_ijk[a]) + 0.5f) * sub;
            corner[a] = int32_t(std::floor((p - grid.origin_cell[a]) / h + 0.5f));
          }
          kernels::lpv_geometry_add(grid, corner, v.coverage * fraction_per_coverage, n, out.data());
        }
  }
}

Status lpv_propagate_volume(const LpvGrid& grid, std::vector<LpvCell> cells, const float* geometry, int iterations,
                            const Context& ctx, std::vector<LpvCell>& accumulated,
                            std::vector<std::array<double, 3>>* flux_per_step) {
  const size_t n = grid.cells();
  if (cells.size() != n) return Status::error(ExitCode::RuntimeFailure, "", "lpv", "cell count mismatch");
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  accumulated = cells;
  std::vector<LpvCell> next(n);
  std::vector<float> scale(n * 3);
  const int planes = grid.dims[2];
  const size_t plane = size_t(grid.dims[0]) * size_t(grid.dims[1]);
  if (flux_per_step) flux_per_step->clear();
  for (int it = 1; it <= iterations; ++it) {
    // LPV rule: no occlusion on the first step (the light is injected beside its own surface).
    const float* occ = (it >= 2) ? geometry : nullptr;
    for_planes(*arena, planes,
               [&](int z0, int z1) { kernels::lpv_flux_scale(grid, cells.data(), scale.data(), z0, z1); });
    for_planes(*arena, planes, [&](int z0, int z1) {
      kernels::lpv_propagate(grid, cells.data(), scale.data(), occ, next.data(), z0, z1);
      kernels::lpv_accumulate(accumulated.data(), next.data(), size_t(z0) * plane, size_t(z1) * plane);
    });
    cells.swap(next);
    if (flux_per_step) {
      std::array<double, 3> f{};
      for (int c = 0; c < 3; ++c) f[c] = kernels::lpv_total_flux(cells.data(), n, c);
      flux_per_step->push_back(f);
    }
    ctx.report("lpv propagate", double(it), double(iterations));
  }
  return Status::ok();
}

namespace {

class CpuLpvDevice final : public LpvDevice {
 public:
  Status propagate(const kernels::LpvGrid& grid, std::vector<kernels::LpvCell> cells, const float* geometry,
                   int iterations, const Context& ctx, std::vector<kernels::LpvCell>& accumulated) override {
    return lpv_propagate_volume(grid, std::move(cells), geometry, iterations, ctx, accumulated);
  }
};

}  // namespace

std::unique_ptr<LpvDevice> make_cpu_lpv_device() { return std::make_unique<CpuLpvDevice>(); }

Status bake_lpv(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                const VoxelGrid* voxels, const LpvSettings& settings, const Context& ctx, LpvResult& out) {
  if (settings.backend.backend != Backend::Cpu)
    return Status::error(ExitCode::RuntimeFailure, "", "lpv", "a device backend needs the device chosen by the caller");
  return bake_lpv(scene, prepared, lights, voxels, settings, ctx, out, make_cpu_lpv_device(), BackendChoice{});
}

Status bake_lpv(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                const VoxelGrid* voxels, const LpvSettings& settings, const Context& ctx, LpvResult& out,
                std::unique_ptr<LpvDevice> device, const BackendChoice& choice) {
  out = LpvResult{};
  out.settings_json = lpv_settings_json(settings, &choice);
  std::vector<LpvGrid> grids;
  GIBAKE_TRY(lpv_cascade_grids(scene.bounds, settings, grids));
  const auto t0 = Clock::now();
  std::vector<kernels::LpvVpl> vpls;
  GIBAKE_TRY(generate_vpls(scene, prepared, lights, settings, ctx, vpls, out.stats));
  const auto t1 = Clock::now();
  out.stats.seconds_vpls = std::chrono::duration<double>(t1 - t0).count();
  if (vpls.empty())
    ctx.warning(
        "lpv: no light reached a surface and nothing is emissive; the LPV is black "
        "(add --sun, lights or emissive materials)");
  const bool occlude = settings.occlusion && voxels && !voxels->empty();
  if (voxels && !voxels->empty()) {
    // Light leaving a surface into closed-off space (the inside of a closed double-sided
    // emitter or wall) never reaches the open scene: drop VPLs whose points 0.5 or 1.5 voxels in
    // front of the surface are Interior (the surface's own voxels, and a conservatively
    // voxelized neighbour, are Surface).
    std::vector<kernels::LpvVpl> kept;
    kept.reserve(vpls.size());
    for (const kernels::LpvVpl& v : vpls) {
      float p[3], q[3];
      for (int a = 0; a < 3; ++a) {
        p[a] = v.position[a] + 0.5f * voxels->voxel_size * v.normal[a];
        q[a] = v.position[a] + 1.5f * voxels->voxel_size * v.normal[a];
      }
      if (voxels->space_at(p) == VoxelSpace::Interior || voxels->space_at(q) == VoxelSpace::Interior) {
        ++out.stats.interior_vpls;
        continue;
      }
      kept.push_back(v);
    }
    vpls.swap(kept);
  }
  for (const LpvGrid& g : grids) {
    std::vector<LpvCell> cells(g.cells());
    out.stats.injected.push_back(kernels::lpv_inject(g, vpls.data(), vpls.size(), cells.data()));
    std::vector<float> geometry;
    if (occlude) lpv_geometry_volume(*voxels, g, geometry);
    const int iterations = settings.iterations > 0 ? settings.iterations : lpv_default_iterations(g);
    std::vector<LpvCell> acc;
    GIBAKE_TRY(device->propagate(g, std::move(cells), occlude ? geometry.data() : nullptr, iterations, ctx, acc));
    LpvCascade c;
    for (int a = 0; a < 3; ++a) {
      c.grid_min[a] = g.origin_cell[a];
      c.dims[a] = g.dims[a];
    }
    c.cell_size = g.cell_size();
    c.iterations = uint32_t(iterations);
    c.occlusion = occlude;
    c.sh.resize(acc.size() * 12);
    for (size_t i = 0; i < acc.size(); ++i)
      for (int ch = 0; ch < 3; ++ch)
        for (int k = 0; k < 4; ++k) c.sh[i * 12 + size_t(ch) * 4 + size_t(k)] = acc[i].sh[ch][k];
    out.cascades.push_back(std::move(c));
  }
  out.stats.seconds_propagate = seconds_since(t1);
  return Status::ok();
}

std::vector<DenseGridExport> lpv_dense_grids(const LpvResult& result) {
  std::vector<DenseGridExport> grids;
  static const char* const kChannel[3] = {"r", "g", "b"};
  for (size_t k = 0; k < result.cascades.size(); ++k) {
    const LpvCascade& c = result.cascades[k];
    const size_t cells = c.cell_count();
    for (int ch = 0; ch < 3; ++ch) {
      DenseGridExport sh0, sh1;
      for (DenseGridExport* g : {&sh0, &sh1}) {
        g->origin = c.grid_min;
        g->voxel_size = c.cell_size;
        g->dims = c.dims;
      }
      const std::string prefix = "lpv" + std::to_string(k) + "_" + kChannel[ch];
      sh0.name = prefix + "_sh0";
      sh0.channels = 1;
      sh1.name = prefix + "_sh1";
      sh1.channels = 3;
      sh0.values.resize(cells);
      sh1.values.resize(cells * 3);
      for (size_t i = 0; i < cells; ++i) {
        const float* s = &c.sh[i * 12 + size_t(ch) * 4];
        sh0.values[i] = s[0];
        sh1.values[i * 3 + 0] = s[3];  // x
        sh1.values[i * 3 + 1] = s[1];  // y
        sh1.values[i * 3 + 2] = s[2];  // z
      }
      grids.push_back(std::move(sh0));
      grids.push_back(std::move(sh1));
    }
  }
  return grids;
}

}  // namespace gibake
