#include "bake/ddgi/refine.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "bake/ddgi/detail_volume.h"
#include "bake/ddgi/probe_grid.h"
#include "bake/voxel/voxelize.h"
#include "io/results/voxel_grid.h"
#include "io/timer.h"
#include "kernels/vec.h"

namespace gibake {

namespace {

constexpr int32_t kMaxVoxelsPerSide = 512;  // the refinement voxels' cap on the scene's longest side
// The least share of chosen bricks in a slab a box grows by, tried in turn while the boxes are too
// many: lower shares take in more bricks that were not chosen and make fewer boxes.
const double kFills[] = {0.5, 0.3, 0.15};

// The default grid's bricks: B cells a side over its cell box (half a spacing beyond the outer probes).
struct BrickGrid {
  std::array<double, 3> lo{}, cell{};
  std::array<int32_t, 3> counts{}, dims{};
  int32_t cells = 2;

  size_t size() const { return size_t(dims[0]) * dims[1] * dims[2]; }
  size_t index(int32_t x, int32_t y, int32_t z) const { return size_t(x) + size_t(dims[0]) * (y + size_t(dims[1]) * z); }
  // The brick coordinates of index i.
  std::array<int32_t, 3> coords(size_t i) const {
    return {int32_t(i % size_t(dims[0])), int32_t(i / size_t(dims[0]) % size_t(dims[1])),
            int32_t(i / size_t(dims[0]) / size_t(dims[1]))};
  }
  void box(const int32_t from[3], const int32_t to[3], std::array<float, 3>& blo, std::array<float, 3>& bhi) const {
    for (int a = 0; a < 3; ++a) {
      blo[a] = float(lo[a] + double(from[a]) * cells * cell[a]);
      bhi[a] = float(lo[a] + double(std::min(to[a] * cells, counts[a])) * cell[a]);
    }
  }
};

bool make_bricks(const DdgiVolumeDesc& d, int32_t cells, BrickGrid& g) {
  g.cells = std::max(1, cells);
  for (int a = 0; a < 3; ++a) {
    if (d.counts[a] < 2 || !(d.spacing[a] > 0.f)) return false;
    g.cell[a] = d.spacing[a];
    g.counts[a] = d.counts[a];
    g.lo[a] = double(d.grid_min[a]) - 0.5 * d.spacing[a];
    g.dims[a] = (d.counts[a] + g.cells - 1) / g.cells;
  }
  return true;
}

using kernels::luminance;

// What a surface voxel sends back: its direct light reflected diffusely, and its emission (cd/m²).
float source_radiance(const SurfaceVoxel& v) {
  const float reflected[3] = {v.direct[0] * v.albedo[0], v.direct[1] * v.albedo[1], v.direct[2] * v.albedo[2]};
  return luminance(reflected) / float(M_PI) + luminance(v.emission);
}

// Each brick's min and max source radiance over the surface voxels within one voxel of it.
void brick_ranges(const VoxelGrid& voxels, const BrickGrid& g, std::vector<float>& lo, std::vector<float>& hi) {
  lo.assign(g.size(), INFINITY);
  hi.assign(g.size(), -INFINITY);
  const double r = voxels.voxel_size;
  for (const SurfaceVoxel& v : voxels.surface) {
    const std::array<float, 3> c = voxels.voxel_center(v.ijk[0], v.ijk[1], v.ijk[2]);
    int32_t from[3], to[3];
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      const double size = g.cells * g.cell[a];
      from[a] = std::max(0, int32_t(std::floor((c[a] - r - g.lo[a]) / size)));
      to[a] = std::min(g.dims[a] - 1, int32_t(std::floor((c[a] + r - g.lo[a]) / size)));
      inside = inside && from[a] <= to[a];
    }
    if (!inside) continue;
    const float s = source_radiance(v);
    for (int32_t z = from[2]; z <= to[2]; ++z)
      for (int32_t y = from[1]; y <= to[1]; ++y)
        for (int32_t x = from[0]; x <= to[0]; ++x) {
          const size_t i = g.index(x, y, z);
          lo[i] = std::min(lo[i], s);
          hi[i] = std::max(hi[i], s);
        }
  }
}

// Per brick, the share of the voxel columns over its x/z footprint that hold a surface voxel
// above the brick (beyond the voxel that straddles its top face): 0 under open sky, 1 under cover.
std::vector<float> brick_cover(const VoxelGrid& voxels, const BrickGrid& g) {
  const int32_t nx = voxels.dims[0], nz = voxels.dims[2];
  std::vector<float> top(size_t(nx) * size_t(nz), -INFINITY);  // the highest surface voxel's centre
  for (const SurfaceVoxel& v : voxels.surface) {
    float& t = top[size_t(v.ijk[0]) + size_t(nx) * size_t(v.ijk[2])];
    t = std::max(t, voxels.voxel_center(v.ijk[0], v.ijk[1], v.ijk[2])[1]);
  }
  // The voxel columns whose centres lie in [lo, hi) along axis a.
  auto columns = [&](int a, float lo, float hi, int32_t& from, int32_t& to) {
    const double f0 = (double(lo) - voxels.origin[a]) / voxels.voxel_size - 0.5;
    const double f1 = (double(hi) - voxels.origin[a]) / voxels.voxel_size - 0.5;
    from = std::clamp(int32_t(std::ceil(f0)), 0, voxels.dims[a]);
    to = std::clamp(int32_t(std::ceil(f1)), from, voxels.dims[a]);
  };
  std::vector<float> cover(g.size(), 0.f);
  for (size_t i = 0; i < g.size(); ++i) {
    const std::array<int32_t, 3> at = g.coords(i);
    const int32_t from[3] = {at[0], at[1], at[2]}, next[3] = {at[0] + 1, at[1] + 1, at[2] + 1};
    std::array<float, 3> lo, hi;
    g.box(from, next, lo, hi);
    int32_t x0, x1, z0, z1;
    columns(0, lo[0], hi[0], x0, x1);
    columns(2, lo[2], hi[2], z0, z1);
    const float above = hi[1] + voxels.voxel_size;
    size_t n = 0, covered = 0;
    for (int32_t z = z0; z < z1; ++z)
      for (int32_t x = x0; x < x1; ++x, ++n) covered += top[size_t(x) + size_t(nx) * size_t(z)] > above;
    cover[i] = n ? float(covered) / float(n) : 0.f;
  }
  return cover;
}

// Whether brick `i` lies inside a volume at least as fine as `spacing`.
bool covered(const BrickGrid& g, size_t i, float spacing, const std::vector<FinerVolume>& finer) {
  const std::array<int32_t, 3> at = g.coords(i);
  const int32_t from[3] = {at[0], at[1], at[2]}, next[3] = {at[0] + 1, at[1] + 1, at[2] + 1};
  std::array<float, 3> lo, hi;
  g.box(from, next, lo, hi);
  for (const FinerVolume& f : finer) {
    if (f.spacing > spacing) continue;
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && lo[a] >= f.lo[a] && hi[a] <= f.hi[a];
    if (inside) return true;
  }
  return false;
}

// The candidate bricks, highest weighted contrast first (ties in brick order), and those contrasts:
// (max - min) x (open_sky_weight + (1 - open_sky_weight) x cover).
void rank_candidates(const BrickGrid& g, const std::vector<float>& lo, const std::vector<float>& hi,
                     const std::vector<float>& cover, float spacing, const std::vector<FinerVolume>& finer,
                     const RefineSettings& s, RefineDecision& out, std::vector<uint32_t>& ranked,
                     std::vector<float>& contrast) {
  contrast.assign(g.size(), 0.f);
  float top = 0.f;
  for (size_t i = 0; i < g.size(); ++i) {
    if (!(hi[i] >= lo[i])) continue;
    ++out.surface_bricks;
    if (!(hi[i] > 0.f) || hi[i] < s.min_contrast * lo[i] || covered(g, i, spacing, finer)) continue;
    contrast[i] = (hi[i] - lo[i]) * (s.open_sky_weight + (1.f - s.open_sky_weight) * cover[i]);
    out.under_cover += cover[i] >= 0.5f;
    top = std::max(top, contrast[i]);
  }
  for (size_t i = 0; i < g.size(); ++i)
    if (contrast[i] > 0.f && contrast[i] >= s.min_share * top) ranked.push_back(uint32_t(i));
  std::stable_sort(ranked.begin(), ranked.end(), [&](uint32_t a, uint32_t b) { return contrast[a] > contrast[b]; });
  out.candidates = ranked.size();
}

// After the changing bricks, the bricks near surfaces around them: ring by ring (6-connected steps
// through the brick grid, at most `rings`), in brick order within a ring.
void add_rings(const BrickGrid& g, const std::vector<float>& lo, const std::vector<float>& hi, float spacing,
               const std::vector<FinerVolume>& finer, int32_t rings, RefineDecision& out,
               std::vector<uint32_t>& ranked) {
  std::vector<int32_t> ring(g.size(), -1);
  std::vector<uint32_t> front(ranked.begin(), ranked.end());
  for (uint32_t i : front) ring[i] = 0;
  std::sort(front.begin(), front.end());
  for (int32_t r = 1; r <= rings && !front.empty(); ++r) {
    std::vector<uint32_t> next;
    for (uint32_t i : front) {
      const std::array<int32_t, 3> at = g.coords(i);
      for (int a = 0; a < 3; ++a)
        for (int32_t step : {-1, 1}) {
          int32_t n[3] = {at[0], at[1], at[2]};
          n[a] += step;
          if (n[a] < 0 || n[a] >= g.dims[a]) continue;
          const size_t j = g.index(n[0], n[1], n[2]);
          if (ring[j] >= 0) continue;
          ring[j] = r;
          next.push_back(uint32_t(j));
        }
    }
    std::sort(next.begin(), next.end());
    for (uint32_t j : next)
      if (hi[j] >= lo[j] && !covered(g, j, spacing, finer)) ranked.push_back(j), ++out.near;
    front = std::move(next);
  }
}

// The share of a slab's cells that are chosen and free; -1 when a cell of it is in another box.
double slab_share(const BrickGrid& g, const std::vector<uint32_t>& chosen, const std::vector<int32_t>& owner,
                  const int32_t from[3], const int32_t to[3]) {
  size_t n = 0, free = 0;
  for (int32_t z = from[2]; z < to[2]; ++z)
    for (int32_t y = from[1]; y < to[1]; ++y)
      for (int32_t x = from[0]; x < to[0]; ++x) {
        const size_t i = g.index(x, y, z);
        if (owner[i] >= 0) return -1.0;
        ++n;
        free += chosen[i] > 0;
      }
  return n ? double(free) / double(n) : -1.0;
}

// Grows the box [from, to) along `axis` while the next slab is at least half chosen and free.
void grow(const BrickGrid& g, const std::vector<uint32_t>& chosen, const std::vector<int32_t>& owner, int axis,
          double fill, int32_t from[3], int32_t to[3]) {
  while (to[axis] < g.dims[axis]) {
    int32_t sf[3] = {from[0], from[1], from[2]}, st[3] = {to[0], to[1], to[2]};
    sf[axis] = to[axis];
    st[axis] = to[axis] + 1;
    if (slab_share(g, chosen, owner, sf, st) < fill) return;
    ++to[axis];
  }
}

// Merges the chosen cells of `g` (chosen[i]: chosen bricks in cell i) into boxes (the rule in refine.h).
void merge_boxes(const BrickGrid& g, const std::vector<uint32_t>& chosen, const std::vector<float>& contrast,
                 float spacing, double fill, std::vector<RefinedBox>& boxes, uint64_t& probes) {
  boxes.clear();
  probes = 0;
  std::vector<int32_t> owner(g.size(), -1);
  for (size_t i = 0; i < g.size(); ++i) {
    if (!chosen[i] || owner[i] >= 0) continue;
    const std::array<int32_t, 3> start = g.coords(i);
    int32_t from[3] = {start[0], start[1], start[2]};
    int32_t to[3] = {from[0] + 1, from[1] + 1, from[2] + 1};
    for (int axis : {0, 2, 1}) grow(g, chosen, owner, axis, fill, from, to);
    RefinedBox box;
    for (int32_t z = from[2]; z < to[2]; ++z)
      for (int32_t y = from[1]; y < to[1]; ++y)
        for (int32_t x = from[0]; x < to[0]; ++x) {
          const size_t j = g.index(x, y, z);
          owner[j] = int32_t(boxes.size());
          box.bricks += chosen[j];
          box.contrast = std::max(box.contrast, contrast[j]);
        }
    g.box(from, to, box.lo, box.hi);
    probes += box_grid_probes(box.lo, box.hi, spacing);
    boxes.push_back(box);
  }
}

// The grid of tiles of t bricks a side, with each tile's chosen bricks and highest contrast.
BrickGrid tiles_of(const BrickGrid& g, int32_t t, const std::vector<uint8_t>& chosen, const std::vector<float>& contrast,
                   std::vector<uint32_t>& count, std::vector<float>& top) {
  BrickGrid tg = g;
  tg.cells = g.cells * t;
  for (int a = 0; a < 3; ++a) tg.dims[a] = (g.counts[a] + tg.cells - 1) / tg.cells;
  count.assign(tg.size(), 0);
  top.assign(tg.size(), 0.f);
  for (size_t i = 0; i < g.size(); ++i) {
    if (!chosen[i]) continue;
    const std::array<int32_t, 3> at = g.coords(i);
    const size_t j = tg.index(at[0] / t, at[1] / t, at[2] / t);
    ++count[j];
    top[j] = std::max(top[j], contrast[i]);
  }
  return tg;
}

// The boxes of the first `k` ranked bricks: merged on tiles of 1, 2, 4, ... bricks, the first tile
// size whose boxes are at most `max_volumes` (coarser tiles take in bricks that were not chosen),
// up to `max_tile` (0: until one tile holds them all).
void boxes_of(const BrickGrid& g, const std::vector<uint32_t>& ranked, const std::vector<float>& contrast, size_t k,
              float spacing, size_t max_volumes, int32_t max_tile, std::vector<RefinedBox>& boxes, uint64_t& probes) {
  std::vector<uint8_t> chosen(g.size(), 0);
  for (size_t j = 0; j < k; ++j) chosen[ranked[j]] = 1;
  int32_t widest = std::max({g.dims[0], g.dims[1], g.dims[2]});
  if (max_tile > 0) widest = std::min(widest, max_tile);
  std::vector<uint32_t> count;
  std::vector<float> top;
  for (int32_t t = 1;; t *= 2) {
    const BrickGrid tg = tiles_of(g, t, chosen, contrast, count, top);
    for (double fill : kFills) {
      merge_boxes(tg, count, top, spacing, fill, boxes, probes);
      if (boxes.size() <= max_volumes) return;
    }
    if (t >= widest) return;
  }
}

// The most ranked bricks whose boxes fit the budget and the volume cap (bisection on the count).
void choose(const BrickGrid& g, const std::vector<uint32_t>& ranked, const std::vector<float>& contrast,
            const RefineSettings& s, RefineDecision& out) {
  const size_t max_volumes = size_t(std::max(0, s.max_volumes));
  auto fits = [&](size_t k, std::vector<RefinedBox>& boxes, uint64_t& probes) {
    boxes_of(g, ranked, contrast, k, out.spacing, max_volumes, s.max_tile, boxes, probes);
    return probes <= s.budget && boxes.size() <= max_volumes;
  };
  size_t good = 0, bad = ranked.size() + 1;
  std::vector<RefinedBox> boxes;
  uint64_t probes = 0;
  if (fits(ranked.size(), boxes, probes)) good = ranked.size(), bad = good + 1;
  while (bad - good > 1) {
    const size_t mid = good + (bad - good) / 2;
    (fits(mid, boxes, probes) ? good : bad) = mid;
  }
  boxes_of(g, ranked, contrast, good, out.spacing, max_volumes, s.max_tile, out.boxes, out.probes);
  out.chosen = good;
}

// A voxelizer's error as the refinement's, naming the way out.
Status refinement_refusal(const Status& st) {
  if (st) return st;
  return Status::error(st.code(), st.file(), "refinement", st.what() + " (or leave refinement out: --refine-budget 0)");
}

// The refinement's voxels over the default grid of `spacing`: a quarter of it, within the cap.
VoxelSettings source_voxel_settings(const Scene& scene, float spacing, float blend_cutoff, uint64_t max_memory_bytes) {
  float longest = 0.f;
  for (int a = 0; a < 3; ++a) longest = std::max(longest, scene.bounds.max[a] - scene.bounds.min[a]);
  VoxelSettings vs;
  vs.voxel_size = std::max(spacing / 4.f, longest / float(kMaxVoxelsPerSide));
  vs.sdf = false;
  vs.blend_cutoff = blend_cutoff;
  vs.max_bytes = max_memory_bytes;
  return vs;
}

// Within --max-memory: a grid over it is refused in one line that names the way out.
Status voxelize_sources(const Scene& scene, const std::vector<kernels::ShadeLight>& lights,
                        const PreparedScene* prepared, float spacing, float blend_cutoff, uint64_t max_memory_bytes,
                        const Context& ctx, VoxelGrid& voxels) {
  const VoxelSettings vs = source_voxel_settings(scene, spacing, blend_cutoff, max_memory_bytes);
  return refinement_refusal(voxelize(scene, vs, lights, prepared, ctx, voxels));
}

std::string decision_text(const RefineDecision& d, const RefineSettings& s) {
  char text[400];
  if (d.candidates == 0) {
    std::snprintf(text, sizeof text,
                  "refinement: none (no brick of %.3g m among %llu near surfaces shows the direct light changing)",
                  double(d.brick_size), (unsigned long long)d.surface_bricks);
    return text;
  }
  const uint64_t changing = std::min(d.chosen, d.candidates), near = d.chosen - changing;
  std::snprintf(text, sizeof text,
                "refinement: %zu volumes at %.3g m, %llu probes (--refine-budget %llu), over %llu bricks of %.3g m: "
                "%llu of the %llu where the direct light changes (%llu of them under cover; under open sky a brick counts a tenth of its contrast) and %llu "
                "of the %llu near surfaces around them",
                d.boxes.size(), double(d.spacing), (unsigned long long)d.probes, (unsigned long long)s.budget,
                (unsigned long long)d.chosen, double(d.brick_size), (unsigned long long)changing,
                (unsigned long long)d.candidates, (unsigned long long)d.under_cover, (unsigned long long)near,
                (unsigned long long)d.near);
  return text;
}

std::string check_decision_text(const RefineDecision& d, uint64_t budget, size_t misses) {
  char text[400];
  if (d.chosen == 0) {
    std::snprintf(text, sizeof text,
                  "refinement by check: none (%zu points of missed patches, no brick of %.3g m left to refine%s)",
                  misses, double(d.brick_size), d.candidates ? " within the budget" : "");
    return text;
  }
  std::snprintf(
      text, sizeof text,
      "refinement by check: %zu volumes at %.3g m, %llu probes (--refine-by-check %llu), over %llu of the %llu "
      "bricks of %.3g m holding the %zu points of patches the check missed",
      d.boxes.size(), double(d.spacing), (unsigned long long)d.probes, (unsigned long long)budget,
      (unsigned long long)d.chosen, (unsigned long long)d.candidates, double(d.brick_size), misses);
  return text;
}

}  // namespace

void decide_check_refinement(const DdgiVolumeDesc& coarse, const std::vector<FinerVolume>& finer,
                             const std::vector<CheckMiss>& misses, uint64_t budget, const RefineSettings& s,
                             RefineDecision& out) {
  out = RefineDecision{};
  BrickGrid g;
  if (budget == 0) return;
  if (!make_bricks(coarse, s.brick_cells, g)) {
    out.text = "refinement by check: none (the default grid has one probe layer on some axis)";
    return;
  }
  out.spacing = min_cell_size(coarse) / 2.f;
  out.brick_size = 2.f * out.spacing * float(g.cells);
  // Each brick's summed error over the missed points inside it (the contrast the boxes report).
  std::vector<float> error(g.size(), 0.f);
  for (const CheckMiss& m : misses) {
    int32_t at[3];
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      at[a] = int32_t(std::floor((double(m.p[a]) - g.lo[a]) / (g.cells * g.cell[a])));
      inside = inside && at[a] >= 0 && at[a] < g.dims[a];
    }
    if (inside) error[g.index(at[0], at[1], at[2])] += m.error;
  }
  std::vector<uint32_t> ranked;
  for (size_t i = 0; i < g.size(); ++i)
    if (error[i] > 0.f && !covered(g, i, out.spacing, finer)) ranked.push_back(uint32_t(i));
  std::stable_sort(ranked.begin(), ranked.end(), [&](uint32_t a, uint32_t b) { return error[a] > error[b]; });
  out.candidates = ranked.size();
  RefineSettings within = s;
  within.budget = budget;
  within.max_tile = 2;
  choose(g, ranked, error, within, out);
  out.text = check_decision_text(out, budget, misses.size());
}

Status refinement_voxel_bytes(const Scene& scene, const DdgiVolumeDesc& coarse, float blend_cutoff,
                              uint64_t max_memory_bytes, uint64_t& bytes) {
  bytes = 0;
  BrickGrid g;
  if (scene.bounds.empty() || !make_bricks(coarse, 1, g)) return Status::ok();  // decide_refinement voxelizes nothing
  VoxelGrid layout;
  const VoxelSettings vs = source_voxel_settings(scene, min_cell_size(coarse), blend_cutoff, max_memory_bytes);
  return refinement_refusal(plan_voxel_grid(scene, vs, layout, bytes));
}

Status decide_refinement(const Scene& scene, const std::vector<kernels::ShadeLight>& lights,
                         const PreparedScene* prepared, const DdgiVolumeDesc& coarse,
                         const std::vector<FinerVolume>& finer, float blend_cutoff, uint64_t max_memory_bytes,
                         const RefineSettings& s, const Context& ctx, RefineDecision& out) {
  out = RefineDecision{};
  if (s.budget == 0) return Status::ok();
  const auto t0 = Clock::now();
  BrickGrid g;
  if (scene.bounds.empty() || !make_bricks(coarse, s.brick_cells, g)) {
    out.text = "refinement: none (the default grid has one probe layer on some axis)";
    return Status::ok();
  }
  const float spacing = min_cell_size(coarse);
  out.spacing = spacing / 2.f;
  out.brick_size = spacing * float(g.cells);
  VoxelGrid voxels;
  GIBAKE_TRY(voxelize_sources(scene, lights, prepared, spacing, blend_cutoff, max_memory_bytes, ctx, voxels));
  std::vector<float> lo, hi, contrast;
  brick_ranges(voxels, g, lo, hi);
  const std::vector<float> cover = brick_cover(voxels, g);
  std::vector<uint32_t> ranked;
  rank_candidates(g, lo, hi, cover, out.spacing, finer, s, out, ranked, contrast);
  add_rings(g, lo, hi, out.spacing, finer, s.rings, out, ranked);
  choose(g, ranked, contrast, s, out);
  out.seconds = seconds_since(t0);
  out.text = decision_text(out, s);
  return Status::ok();
}

}  // namespace gibake
