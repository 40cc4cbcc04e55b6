#include "bake/voxel/voxelize.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "bake/run/arena.h"
#include "bake/scene/prepare.h"
#include "bake/voxel/voxel_internal.h"
#include "bake/voxel/voxel_raster.h"
#include "io/size_text.h"
#include "io/timer.h"

namespace gibake {
using voxel::Fragment;

namespace {


constexpr uint32_t kChunk = 2048;           // triangles per task: fixed, so merging order is fixed
// Occupancy has no order to keep (stores and counts): smaller tasks spread a few large triangles
// over more threads.
constexpr uint32_t kOccupancyChunk = 256;
constexpr double kMaxAxisVoxels = 1 << 30;  // int32 coordinates with room for padding

Status bad(const std::string& what, const std::string& file = "") {
  return Status::error(ExitCode::BadArguments, file, "voxelize", what);
}

bool finite3(const float* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

bool triangle_finite(const Scene& s, size_t t) {
  for (int k = 0; k < 3; ++k)
    if (!finite3(&s.positions[size_t(s.indices[t * 3 + k]) * 3])) return false;
  return true;
}

// Runs f(c) for every chunk c of kChunk triangles: in `arena` when given, else on this thread.
template <class F>
void for_triangle_chunks(const Scene& s, tbb::task_arena* arena, F&& f) {
  const size_t chunks = (s.triangle_count() + kChunk - 1) / kChunk;
  if (!arena) {
    for (size_t c = 0; c < chunks; ++c) f(c);
    return;
  }
  arena->execute([&] { tbb::parallel_for(size_t(0), chunks, [&](size_t c) { f(c); }); });
}

// Bounds of the finite triangles (not Scene::bounds, which test scenes may leave stale), per
// chunk and then merged (min and max are exact in any order).
Bounds triangle_bounds(const Scene& s, tbb::task_arena* arena) {
  std::vector<Bounds> part((s.triangle_count() + kChunk - 1) / kChunk);
  for_triangle_chunks(s, arena, [&](size_t c) {
    Bounds& b = part[c];
    for (size_t t = c * kChunk; t < std::min(s.triangle_count(), (c + 1) * kChunk); ++t) {
      if (!triangle_finite(s, t)) continue;
      for (int k = 0; k < 3; ++k) {
        const float* p = &s.positions[size_t(s.indices[t * 3 + k]) * 3];
        b.extend({p[0], p[1], p[2]});
      }
    }
  });
  Bounds b;
  for (const Bounds& pb : part)
    if (!pb.empty()) {
      b.extend(pb.min);
      b.extend(pb.max);
    }
  return b;
}

// Upper bound on the voxels one triangle overlaps, in voxel units: every overlapped voxel's
// centre lies within sqrt(3)/2 of the triangle, so the count is at most the volume of the
// triangle grown by sqrt(3) (Steiner: 2rA + (pi/2) r^2 P + (4/3) pi r^3 with r = sqrt(3)),
// and at most its voxel range.
double triangle_fragment_bound(const double v[3][3]) {
  double e[3][3], per = 0.0, box = 1.0;
  for (int k = 0; k < 3; ++k) {
    for (int a = 0; a < 3; ++a) e[k][a] = v[(k + 1) % 3][a] - v[k][a];
    per += std::sqrt(e[k][0] * e[k][0] + e[k][1] * e[k][1] + e[k][2] * e[k][2]);
  }
  const double cx = e[0][1] * e[2][2] - e[0][2] * e[2][1], cy = e[0][2] * e[2][0] - e[0][0] * e[2][2],
               cz = e[0][0] * e[2][1] - e[0][1] * e[2][0];
  const double area = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
  for (int a = 0; a < 3; ++a) {
    const double mn = std::min({v[0][a], v[1][a], v[2][a]}), mx = std::max({v[0][a], v[1][a], v[2][a]});
    box *= std::floor(mx) - std::ceil(mn) + 3.0;
  }
  const double r = std::sqrt(3.0), pi = 3.14159265358979;
  return std::min(box, 2.0 * r * area + 0.5 * pi * r * r * per + 4.0 / 3.0 * pi * r * r * r);
}

}  // namespace

std::string voxel_settings_json(const VoxelSettings& s) {
  nlohmann::json j{{"voxel_size", s.voxel_size},
                   {"resolution", s.resolution},
                   {"padding", s.padding},
                   {"channels", s.channels},
                   {"sdf", s.sdf},
                   {"blend_cutoff", s.blend_cutoff}};
  return j.dump();
}

Status plan_voxel_grid(const Scene& scene, const VoxelSettings& s, VoxelGrid& layout, uint64_t& estimated_bytes,
                       tbb::task_arena* arena) {
  if (!(s.voxel_size >= 0.f) || !std::isfinite(s.voxel_size))
    return bad("voxel size must be a positive number of metres");
  if (s.voxel_size == 0.f && (s.resolution < 1 || s.resolution > (1 << 20)))
    return bad("voxel resolution must be between 1 and 1048576 voxels on the longest axis, got " +
               std::to_string(s.resolution));
  if (s.padding < 1 || s.padding > 1024) return bad("voxel padding must be between 1 and 1024 voxels");
  for (int32_t e : s.low_extra)
    if (e < 0 || e > 1024) return bad("extra low voxels must be between 0 and 1024");
  const Bounds b = triangle_bounds(scene, arena);
  if (b.empty())
    return Status::invalid(scene.source_path, "voxelize", "the scene has no triangles with finite vertices");
  double longest = 0.0;
  for (int a = 0; a < 3; ++a) longest = std::max(longest, double(b.max[a]) - double(b.min[a]));
  // A scene of one point (zero-area triangles all at one place) gets 1 m voxels.
  const double size = s.voxel_size > 0.f ? double(s.voxel_size) : (longest > 0.0 ? longest / s.resolution : 1.0);
  if (!(size > 0.0) || !std::isfinite(float(size))) return bad("voxel size underflows");
  double voxels = 1.0;
  std::array<double, 3> dims{};
  for (int a = 0; a < 3; ++a) {
    const double m = (double(b.max[a]) - double(b.min[a])) / size;
    dims[a] = std::ceil(m) + 2.0 * s.padding + 1.0 + double(s.low_extra[size_t(a)]);
    voxels *= dims[a];
  }
  char what[256];
  if (dims[0] > kMaxAxisVoxels || dims[1] > kMaxAxisVoxels || dims[2] > kMaxAxisVoxels || voxels > 0x1p42) {
    std::snprintf(what, sizeof what,
                  "a voxel size of %g m gives %.3gx%.3gx%.3g voxels, beyond 2^30 per axis or 2^42 in all", size,
                  dims[0], dims[1], dims[2]);
    return bad(what, scene.source_path);
  }
  // Working set: the space array, fragments (twice while they are merged) and surface voxels
  // (bounded per triangle), the SDF's dense arrays and band, Embree's BVH when lights are traced.
  double fragments = 0.0;
  layout = VoxelGrid{};
  layout.voxel_size = float(size);
  for (int a = 0; a < 3; ++a) {
    layout.dims[a] = int32_t(dims[a]);
    const double centre = 0.5 * (double(b.min[a]) + double(b.max[a]));
    const double extra = double(s.low_extra[size_t(a)]);
    layout.origin[a] = float(centre - 0.5 * (dims[a] - extra) * size - extra * size);
  }
  // Per chunk, then the chunks' sums in chunk order: the same figure for any thread count.
  std::vector<double> part((scene.triangle_count() + kChunk - 1) / kChunk, 0.0);
  for_triangle_chunks(scene, arena, [&](size_t c) {
    for (size_t t = c * kChunk; t < std::min(scene.triangle_count(), (c + 1) * kChunk); ++t) {
      if (!triangle_finite(scene, t)) continue;
      double v[3][3];
      voxel::triangle_in_voxels(scene, layout, uint32_t(t), v);
      part[c] += triangle_fragment_bound(v);
    }
  });
  for (double f : part) fragments += f;
  fragments = std::min(fragments, voxels * double(scene.triangle_count()));
  const double surface = std::min(fragments, voxels);
  double bytes = voxels + fragments * 2.0 * sizeof(Fragment) + surface * sizeof(SurfaceVoxel) +
                 double(scene.triangle_count()) * 128.0;
  if (s.sdf) bytes += voxel::sdf_bytes_estimate(voxels, surface);
  estimated_bytes = bytes > 1.8e19 ? UINT64_MAX : uint64_t(bytes);
  if (bytes > double(s.max_bytes)) {
    std::snprintf(what, sizeof what,
                  "a %dx%dx%d voxel grid (%.4g m voxels) needs about %s, over the %s of --max-memory; use a larger "
                  "voxel size or a lower resolution or raise --max-memory",
                  layout.dims[0], layout.dims[1], layout.dims[2], size, size_text(bytes).c_str(),
                  size_text(double(s.max_bytes)).c_str());
    return bad(what, scene.source_path);
  }
  return Status::ok();
}

namespace {

// Rasterizes triangles [first, last) in triangle order, calling voxel(t, x, y, z) for every
// voxel a triangle overlaps; counts skipped and degenerate triangles.
template <class VoxelFn>
void rasterize_range(const Scene& scene, const VoxelGrid& g, size_t first, size_t last, uint64_t& skipped,
                     uint64_t& degenerate, VoxelFn&& voxel) {
  const int32_t dims[3] = {g.dims[0], g.dims[1], g.dims[2]};
  for (size_t t = first; t < std::min(scene.triangle_count(), last); ++t) {
    if (!triangle_finite(scene, t)) {
      ++skipped;
      continue;
    }
    double v[3][3];
    voxel::triangle_in_voxels(scene, g, uint32_t(t), v);
    int32_t ijk[3];
    bool single_degenerate = false;
    if (voxel::single_voxel(v, dims, ijk, single_degenerate)) {  // most small triangles fit one voxel
      if (single_degenerate) ++degenerate;
      voxel(t, ijk[0], ijk[1], ijk[2]);
      continue;
    }
    const voxel::TriangleRaster tr = voxel::setup_triangle(v[0], v[1], v[2], dims);
    if (tr.degenerate) ++degenerate;
    voxel::rasterize_triangle(tr, [&](int32_t x, int32_t y, int32_t z) { voxel(t, x, y, z); });
  }
}

// Fragments of every triangle, grouped by z-layer and, within a layer, in triangle order:
// chunks of kChunk triangles rasterize in parallel, then scatter into their layer's slots in
// chunk order. Returns the layer start offsets (dims[2] + 1 entries).
std::vector<size_t> rasterize_all(const Scene& scene, const VoxelGrid& g, tbb::task_arena& arena,
                                  std::vector<Fragment>& out, VoxelReport& rep) {
  const size_t tris = scene.triangle_count();
  const size_t chunks = (tris + kChunk - 1) / kChunk;
  const size_t Z = size_t(g.dims[2]);
  std::vector<std::vector<Fragment>> parts(chunks);
  std::vector<uint64_t> skipped(chunks, 0), degenerate(chunks, 0);
  std::vector<size_t> counts(chunks * Z, 0);  // [chunk][z]
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, chunks, 1),
        [&](const tbb::blocked_range<size_t>& r) {
          for (size_t c = r.begin(); c != r.end(); ++c) {
            std::vector<Fragment>& frags = parts[c];
            size_t* cnt = &counts[c * Z];
            rasterize_range(scene, g, c * kChunk, (c + 1) * kChunk, skipped[c], degenerate[c],
                            [&](size_t t, int32_t x, int32_t y, int32_t z) {
              frags.push_back(Fragment{g.linear(x, y, z), uint32_t(t)});
              ++cnt[z];
            });
          }
        },
        tbb::simple_partitioner());
  });
  std::vector<size_t> layer_start(Z + 1, 0), cursor(chunks * Z);
  size_t total = 0;
  for (size_t z = 0; z < Z; ++z) {
    layer_start[z] = total;
    for (size_t c = 0; c < chunks; ++c) {
      cursor[c * Z + z] = total;
      total += counts[c * Z + z];
    }
  }
  layer_start[Z] = total;
  for (size_t c = 0; c < chunks; ++c) {
    rep.skipped_triangles += skipped[c];
    rep.degenerate_triangles += degenerate[c];
  }
  out.resize(total);
  const int64_t layer_size = int64_t(g.dims[0]) * g.dims[1];
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, chunks, 1),
        [&](const tbb::blocked_range<size_t>& r) {
          for (size_t c = r.begin(); c != r.end(); ++c) {
            for (const Fragment& f : parts[c]) out[cursor[c * Z + size_t(f.voxel / layer_size)]++] = f;
            std::vector<Fragment>().swap(parts[c]);
          }
        },
        tbb::simple_partitioner());
  });
  rep.fragments = total;
  return layer_start;
}

// Per z-layer: sort the layer's fragments by voxel (then triangle), mark surface voxels and build
// their records (channels when `in` is given). Layers own disjoint parts of `space`.
void build_surface(const std::vector<size_t>& layer_start, std::vector<Fragment>& frags, const voxel::ChannelInputs* in,
                   tbb::task_arena& arena, VoxelGrid& g, VoxelReport& rep) {
  const size_t Z = size_t(g.dims[2]);
  std::vector<std::vector<SurfaceVoxel>> layers(Z);
  std::vector<uint64_t> rays(Z, 0);
  const int64_t X = g.dims[0], XY = int64_t(g.dims[0]) * g.dims[1];
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, Z, 1),
        [&](const tbb::blocked_range<size_t>& r) {
          for (size_t z = r.begin(); z != r.end(); ++z) {
            Fragment* b = frags.data() + layer_start[z];
            Fragment* e = frags.data() + layer_start[z + 1];
            std::sort(b, e, [](const Fragment& x, const Fragment& y) {
              return x.voxel != y.voxel ? x.voxel < y.voxel : x.tri < y.tri;
            });
            for (Fragment* run = b; run != e;) {
              Fragment* end = run;
              while (end != e && end->voxel == run->voxel) ++end;
              SurfaceVoxel sv;
              const int64_t li = run->voxel;
              sv.ijk[0] = int32_t(li % X);
              sv.ijk[1] = int32_t((li / X) % g.dims[1]);
              sv.ijk[2] = int32_t(li / XY);
              sv.fragments = uint32_t(end - run);
              if (in) rays[z] += voxel::fill_channels(*in, run, size_t(end - run), sv);
              g.space[size_t(li)] = uint8_t(VoxelSpace::Surface);
              layers[z].push_back(sv);
              run = end;
            }
          }
        },
        tbb::simple_partitioner());
  });
  size_t n = 0;
  for (const auto& l : layers) n += l.size();
  g.surface.reserve(n);
  for (size_t z = 0; z < Z; ++z) {
    g.surface.insert(g.surface.end(), layers[z].begin(), layers[z].end());
    rep.shadow_rays += rays[z];
    std::vector<SurfaceVoxel>().swap(layers[z]);
  }
}

// Occupancy alone (no channels): every triangle marks its voxels in `space` and counts itself in
// a per-voxel counter, with no fragment list to sort. Stores of Surface are idempotent and counts
// are sums, so the result is the fragment path's for any thread schedule: `surface` is built in
// linear order (the fragment path's order) with the same fragment counts.
void build_occupancy(const Scene& scene, tbb::task_arena& arena, VoxelGrid& g, VoxelReport& rep) {
  const size_t tris = scene.triangle_count();
  const size_t chunks = (tris + kOccupancyChunk - 1) / kOccupancyChunk;
  std::vector<uint64_t> skipped(chunks, 0), degenerate(chunks, 0), frags(chunks, 0);
  std::unique_ptr<std::atomic<uint32_t>[]> count(new std::atomic<uint32_t>[g.space.size()]);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), g.space.size(), [&](size_t i) { count[i].store(0, std::memory_order_relaxed); });
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, chunks, 1),
        [&](const tbb::blocked_range<size_t>& r) {
          for (size_t c = r.begin(); c != r.end(); ++c)
            rasterize_range(scene, g, c * kOccupancyChunk, (c + 1) * kOccupancyChunk, skipped[c], degenerate[c],
                            [&](size_t, int32_t x, int32_t y, int32_t z) {
              count[size_t(g.linear(x, y, z))].fetch_add(1, std::memory_order_relaxed);
              ++frags[c];
            });
        },
        tbb::simple_partitioner());
  });
  for (size_t c = 0; c < chunks; ++c) {
    rep.skipped_triangles += skipped[c];
    rep.degenerate_triangles += degenerate[c];
    rep.fragments += frags[c];
  }
  // The surface list in linear order, z-slab by z-slab in parallel: each slab's count, their
  // prefix sums, then each slab fills its own range.
  const size_t X = size_t(g.dims[0]), XY = X * size_t(g.dims[1]), Z = size_t(g.dims[2]);
  std::vector<size_t> slab_start(Z + 1, 0);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), Z, [&](size_t z) {
      size_t n = 0;
      for (size_t i = z * XY; i < (z + 1) * XY; ++i) n += count[i].load(std::memory_order_relaxed) != 0;
      slab_start[z + 1] = n;
    });
  });
  for (size_t z = 0; z < Z; ++z) slab_start[z + 1] += slab_start[z];
  g.surface.resize(slab_start[Z]);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), Z, [&](size_t z) {
      size_t out = slab_start[z];
      for (size_t i = z * XY; i < (z + 1) * XY; ++i) {
        const uint32_t n = count[i].load(std::memory_order_relaxed);
        if (n == 0) continue;
        SurfaceVoxel& sv = g.surface[out++];
        sv.ijk[0] = int32_t(i % X);
        sv.ijk[1] = int32_t((i / X) % size_t(g.dims[1]));
        sv.ijk[2] = int32_t(z);
        sv.fragments = n;
        g.space[i] = uint8_t(VoxelSpace::Surface);
      }
    });
  });
}

Status finish_voxelize(const VoxelSettings& settings, tbb::task_arena& arena, const Context& ctx,
                       Clock::time_point t_all, const Scene& scene, VoxelGrid& g, VoxelReport& rep, VoxelGrid& out,
                       VoxelReport* report);

Status voxelize_with(const Scene& scene, const VoxelSettings& settings, const std::vector<kernels::ShadeLight>& lights,
                     const PreparedScene* prepared, const Context& ctx, tbb::task_arena* shared, VoxelGrid& out,
                     VoxelReport* report);

}  // namespace

Status voxelize(const Scene& scene, const VoxelSettings& settings, const Context& ctx, VoxelGrid& out,
                VoxelReport* report) {
  static const std::vector<kernels::ShadeLight> kNoLights;
  return voxelize_with(scene, settings, kNoLights, nullptr, ctx, nullptr, out, report);
}

Status voxelize_in(tbb::task_arena& arena, const Scene& scene, const VoxelSettings& settings, const Context& ctx,
                   VoxelGrid& out, VoxelReport* report) {
  static const std::vector<kernels::ShadeLight> kNoLights;
  return voxelize_with(scene, settings, kNoLights, nullptr, ctx, &arena, out, report);
}

Status voxelize(const Scene& scene, const VoxelSettings& settings, const std::vector<kernels::ShadeLight>& lights,
                const PreparedScene* prepared, const Context& ctx, VoxelGrid& out, VoxelReport* report) {
  return voxelize_with(scene, settings, lights, prepared, ctx, nullptr, out, report);
}

namespace {

Status voxelize_with(const Scene& scene, const VoxelSettings& settings, const std::vector<kernels::ShadeLight>& lights,
                     const PreparedScene* prepared, const Context& ctx, tbb::task_arena* shared, VoxelGrid& out,
                     VoxelReport* report) {
  const auto t_all = Clock::now();
  VoxelReport rep;
  VoxelGrid g;
  uint64_t estimate = 0;
  std::unique_ptr<tbb::task_arena> own_arena = shared ? nullptr : make_arena(ctx);
  tbb::task_arena* arena = shared ? shared : own_arena.get();
  GIBAKE_TRY(plan_voxel_grid(scene, settings, g, estimate, arena));
  rep.estimated_bytes = estimate;
  rep.dims = g.dims;
  rep.voxel_size = g.voxel_size;
  rep.triangles = scene.triangle_count();

  auto t0 = Clock::now();
  if (!settings.channels) {
    g.space.assign(size_t(g.linear(g.dims[0] - 1, g.dims[1] - 1, g.dims[2] - 1)) + 1, voxel::kUnvisited);
    build_occupancy(scene, *arena, g, rep);
    rep.stage_seconds.emplace_back("surface", seconds_since(t0));
    ctx.report("voxelize", 2, 4);
    return finish_voxelize(settings, *arena, ctx, t_all, scene, g, rep, out, report);
  }
  std::vector<Fragment> frags;
  const std::vector<size_t> layer_start = rasterize_all(scene, g, *arena, frags, rep);
  rep.stage_seconds.emplace_back("rasterize", seconds_since(t0));
  ctx.report("voxelize", 1, 4);

  std::unique_ptr<PreparedScene> own_prepared;
  const bool trace = !lights.empty();
  if (trace && !prepared) {
    t0 = Clock::now();
    PrepareOptions po;
    po.blend_cutoff = settings.blend_cutoff;
    GIBAKE_TRY(PreparedScene::create(scene, ctx, own_prepared, po));
    prepared = own_prepared.get();
    rep.stage_seconds.emplace_back("prepare", seconds_since(t0));
  }
  t0 = Clock::now();
  g.space.assign(size_t(g.linear(g.dims[0] - 1, g.dims[1] - 1, g.dims[2] - 1)) + 1, voxel::kUnvisited);
  voxel::ChannelInputs in;
  in.scene = &scene;
  in.grid = &g;
  in.lights = trace ? &lights : nullptr;
  in.prepared = prepared;
  in.blend_cutoff = settings.blend_cutoff;
  build_surface(layer_start, frags, &in, *arena, g, rep);
  std::vector<Fragment>().swap(frags);
  rep.stage_seconds.emplace_back("channels", seconds_since(t0));
  ctx.report("voxelize", 2, 4);
  return finish_voxelize(settings, *arena, ctx, t_all, scene, g, rep, out, report);
}

// Flood fill, counts and the SDF: the same after either surface path.
Status finish_voxelize(const VoxelSettings& settings, tbb::task_arena& arena, const Context& ctx,
                       Clock::time_point t_all, const Scene& scene, VoxelGrid& g, VoxelReport& rep, VoxelGrid& out,
                       VoxelReport* report) {
  auto t0 = Clock::now();
  voxel::flood_fill_exterior(g.dims, g.space);
  rep.stage_seconds.emplace_back("flood_fill", seconds_since(t0));
  for (uint8_t v : g.space) {
    if (v == uint8_t(VoxelSpace::Exterior))
      ++rep.exterior_voxels;
    else if (v == uint8_t(VoxelSpace::Interior))
      ++rep.interior_voxels;
  }
  rep.surface_voxels = g.surface.size();
  ctx.report("voxelize", 3, 4);

  if (settings.sdf) {
    t0 = Clock::now();
    GIBAKE_TRY(voxel::compute_sdf(scene, arena, g));
    rep.stage_seconds.emplace_back("sdf", seconds_since(t0));
  }
  ctx.report("voxelize", 4, 4);
  rep.seconds_total = seconds_since(t_all);
  out = std::move(g);
  if (report) *report = std::move(rep);
  return Status::ok();
}

}  // namespace

}  // namespace gibake
