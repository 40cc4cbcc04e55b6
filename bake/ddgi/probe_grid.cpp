#include "bake/ddgi/probe_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace gibake {

namespace {
Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "probe grid", what); }

}  // namespace

double cells_along(float extent, float spacing, bool fitted) {
  return fitted ? std::floor(double(extent) / spacing - 0.5 + 1e-4) + 1.0 : std::ceil(double(extent) / spacing - 1e-4);
}

namespace {
uint64_t probes_at(const std::array<float, 3>& extent, float spacing) {
  uint64_t n = 1;
  for (float e : extent) n *= uint64_t(std::max(1.0, cells_along(e, spacing, false)));
  return n;
}

// The default rule's box [lo, hi] fitted to the voxels; what the rule gave before goes to `out`.
void fit_box(const VoxelGrid& voxels, const GridSettings& s, std::array<float, 3>& lo, std::array<float, 3>& hi,
             GridPlacement& out) {
  const std::array<float, 3> extent{hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  out.unfitted_spacing = default_probe_spacing(extent, s);
  out.unfitted_probes = probes_at(extent, out.unfitted_spacing);
  // The fit reads the scene's box; --grid-padding then pads the fitted box as it padded the whole.
  std::array<float, 3> scene_lo{}, scene_hi{};
  for (int a = 0; a < 3; ++a) scene_lo[a] = lo[a] + s.padding, scene_hi[a] = hi[a] - s.padding;
  out.fit = fit_probe_box(voxels, scene_lo, scene_hi);
  if (!out.fit.fitted) return;
  for (int a = 0; a < 3; ++a) lo[a] = out.fit.lo[a] - s.padding, hi[a] = out.fit.hi[a] + s.padding;
}
// One layer of probes outside each open side of the box (probe_fit.h), a spacing beyond the
// outermost, unless the layers would take the grid past the probe budget (or --grid-padding
// already chose how far the grid reaches past the box: the caller's test).
void add_outer_layers(const std::array<double, 3>& step, uint64_t budget, std::array<int64_t, 3>& counts,
                      std::array<float, 3>& lo, std::array<float, 3>& hi, GridPlacement& out) {
  std::array<int64_t, 3> more = counts;
  for (int side = 0; side < 6; ++side)
    if (out.fit.open[side] && step[side / 2] > 0.0) ++more[side / 2];
  if (more == counts || uint64_t(more[0]) * uint64_t(more[1]) * uint64_t(more[2]) > budget) return;
  for (int side = 0; side < 6; ++side) {
    const int a = side / 2;
    if (!out.fit.open[side] || !(step[a] > 0.0)) continue;
    if (side % 2 == 0) lo[a] = static_cast<float>(double(lo[a]) - step[a]);
    else hi[a] = static_cast<float>(double(hi[a]) + step[a]);
    out.outer_layer[side] = true;
  }
  counts = more;
}

// The box the grid spans before its cells are laid out: the given bounds, or the scene's padded.
Status grid_box(const Scene& scene, const GridSettings& s, bool have_counts, std::array<float, 3>& lo,
                std::array<float, 3>& hi) {
  if (s.explicit_bounds) {
    if (!have_counts) return bad("--grid-min/--grid-max need --probe-counts");
    lo = s.grid_min;
    hi = s.grid_max;
    for (int a = 0; a < 3; ++a)
      if (!(hi[a] >= lo[a]) || !std::isfinite(lo[a]) || !std::isfinite(hi[a]))
        return bad("grid max must not be below grid min on any axis");
    return Status::ok();
  }
  if (scene.bounds.empty()) return bad("the scene has no geometry; give --grid-min/--grid-max/--probe-counts");
  if (!(s.padding >= 0.f)) return bad("padding must be non-negative");
  for (int a = 0; a < 3; ++a) {
    lo[a] = scene.bounds.min[a] - s.padding;
    hi[a] = scene.bounds.max[a] + s.padding;
  }
  return Status::ok();
}

// Probes per axis and their step from the spacing (given, or the rule on the box, which is first
// fitted to the voxels when the rule decides: `ran_fit`).
Status grid_cells(const GridSettings& s, const VoxelGrid* voxels, std::array<float, 3>& lo, std::array<float, 3>& hi,
                  std::array<int64_t, 3>& counts, std::array<double, 3>& step, bool& ran_fit, GridPlacement& out) {
  if (s.spacing < 0.f || !std::isfinite(s.spacing)) return bad("probe spacing must be positive");
  if (s.spacing == 0.f && s.fit_to_voxels && voxels && !s.explicit_bounds) {
    fit_box(*voxels, s, lo, hi, out);
    ran_fit = true;
  }
  const std::array<float, 3> extent{hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  // On a fitted box the rule runs on the fitted extent. The probes the fit saves are not spent on
  // a finer grid: that costs bake time for a picture within the spread that shifting the grid by
  // half a cell gives (docs/BENCHMARKS.md "The picture").
  const float spacing = s.spacing > 0.f ? s.spacing : default_probe_spacing(extent, s, out.fit.fitted);
  for (int a = 0; a < 3; ++a) {
    // A fitted box ends at walls, floors and ceilings, and the cell rule can put the outermost
    // probes within a hair of them (an extent just over n cells gets n + 1, its probes on the
    // walls: two_rooms' lit room got probes on its floor, ceiling and walls, black patches where
    // none weighed in). There the probes keep between a quarter and three quarters of a spacing
    // from every face of the box.
    const double cells = cells_along(extent[a], spacing, out.fit.fitted);
    if (cells > 1e7) return bad("probe spacing too small for the scene size");
    counts[a] = std::max<int64_t>(1, static_cast<int64_t>(cells));
    step[a] = spacing;
  }
  return Status::ok();
}

// One probe at the centre of each cell; with a given spacing the cells keep it exactly and the
// grid is centred on the box, otherwise the box is divided evenly.
void centre_cells(const std::array<double, 3>& step, const std::array<int64_t, 3>& counts, std::array<float, 3>& lo,
                  std::array<float, 3>& hi) {
  for (int a = 0; a < 3; ++a) {
    const double d = step[a] > 0.0 ? step[a] : (double(hi[a]) - lo[a]) / double(counts[a]);
    const double centre = 0.5 * (double(lo[a]) + hi[a]);
    const double span = double(counts[a] - 1) * d;
    lo[a] = static_cast<float>(centre - 0.5 * span);
    hi[a] = static_cast<float>(centre + 0.5 * span);
  }
}

// The volume's record from its counts and outer probes, within the probe cap.
Status grid_desc(const GridSettings& s, const std::array<int64_t, 3>& counts, const std::array<float, 3>& lo,
                 const std::array<float, 3>& hi, DdgiVolumeDesc& desc) {
  const uint64_t total = uint64_t(counts[0]) * uint64_t(counts[1]) * uint64_t(counts[2]);
  if (total > s.max_probes)
    return bad(std::to_string(counts[0]) + "x" + std::to_string(counts[1]) + "x" + std::to_string(counts[2]) + " = " +
               std::to_string(total) + " probes exceeds the cap of " + std::to_string(s.max_probes) +
               "; use a larger --probe-spacing or fewer --probe-counts");
  for (int a = 0; a < 3; ++a) {
    desc.counts[a] = static_cast<int32_t>(counts[a]);
    desc.grid_min[a] = lo[a];
    desc.grid_max[a] = counts[a] > 1 ? hi[a] : lo[a];
    if (counts[a] == 1) desc.grid_min[a] = desc.grid_max[a] = 0.5f * (lo[a] + hi[a]);
    desc.spacing[a] = counts[a] > 1 ? (desc.grid_max[a] - desc.grid_min[a]) / float(counts[a] - 1) : 0.f;
    // Several probes on one spot of a flat scene's box (a floor alone). Given bounds are the
    // caller's: the CLI refuses equal ones, and coincident probes serve the library's statistics.
    if (!s.explicit_bounds && counts[a] > 1 && !(desc.spacing[a] > 0.f)) {
      const std::string axis(1, "xyz"[a]);
      return bad(std::to_string(counts[a]) + " probes along " + axis +
                 " over the scene's box (padded by --grid-padding), which has no depth on " + axis +
                 ": give 1 probe there, --grid-padding or --grid-min/--grid-max");
    }
  }
  return Status::ok();
}
}  // namespace

float miss_depth(const Bounds& scene, const std::vector<const DdgiVolumeDesc*>& grids) {
  Bounds all = scene;
  for (const DdgiVolumeDesc* d : grids) {
    all.extend({d->grid_min[0], d->grid_min[1], d->grid_min[2]});
    all.extend({d->grid_max[0], d->grid_max[1], d->grid_max[2]});
  }
  const float diag = std::sqrt((all.max[0] - all.min[0]) * (all.max[0] - all.min[0]) +
                               (all.max[1] - all.min[1]) * (all.max[1] - all.min[1]) +
                               (all.max[2] - all.min[2]) * (all.max[2] - all.min[2]));
  return std::max(1.5f * diag, 1.f);
}

Status place_probe_grid(const Scene& scene, const GridSettings& s, DdgiVolumeDesc& desc, const VoxelGrid* voxels,
                        GridPlacement* placement) {
  GridPlacement local;
  GridPlacement& out = placement ? *placement : local;
  out = GridPlacement{};
  const bool have_counts = s.counts[0] > 0 && s.counts[1] > 0 && s.counts[2] > 0;
  if (s.counts[0] < 0 || s.counts[1] < 0 || s.counts[2] < 0) return bad("probe counts must be positive");
  std::array<float, 3> lo{}, hi{};
  GIBAKE_TRY(grid_box(scene, s, have_counts, lo, hi));
  std::array<int64_t, 3> counts{};
  std::array<double, 3> step{};
  bool ran_fit = false;
  if (have_counts)
    for (int a = 0; a < 3; ++a) counts[a] = s.counts[a];
  else
    GIBAKE_TRY(grid_cells(s, voxels, lo, hi, counts, step, ran_fit, out));
  if (!s.explicit_bounds) {
    centre_cells(step, counts, lo, hi);
    if (ran_fit && !(s.padding > 0.f)) add_outer_layers(step, s.auto_max_probes, counts, lo, hi, out);
  }
  return grid_desc(s, counts, lo, hi, desc);
}

float default_probe_spacing(const std::array<float, 3>& extent, const GridSettings& s, bool fitted) {
  const float longest = std::max({extent[0], extent[1], extent[2]});
  float spacing = longest > 0.f ? longest / float(std::max(1, s.auto_cells)) : 1.f;
  const float floor = longest > 0.f ? std::min(s.auto_min_spacing, longest / float(std::max(1, s.auto_min_cells)))
                                    : s.auto_min_spacing;
  spacing = std::min(std::max(spacing, floor), std::max(floor, s.auto_max_spacing));
  auto probes = [&](float d) {
    double n = 1.0;
    for (float e : extent) n *= std::max(1.0, cells_along(e, d, fitted));
    return n;
  };
  while (probes(spacing) > double(std::max<uint64_t>(1, s.auto_max_probes))) spacing *= 1.05f;
  return spacing;
}

namespace {
const char* kSide[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};

// "one layer outside the open side(s) -z, +z (...)", or "" when none was added.
std::string outer_layers_text(const GridPlacement& p) {
  std::string sides;
  for (int side = 0; side < 6; ++side)
    if (p.outer_layer[side]) sides += std::string(sides.empty() ? "" : ", ") + kSide[side];
  if (sides.empty()) return "";
  return "one layer of probes outside the open side" + std::string(sides.size() > 2 ? "s " : " ") + sides +
         " (surfaces end there beside open space and face out of the scene)";
}
}  // namespace

std::string placement_text(const GridPlacement& p) {
  const std::string outer = outer_layers_text(p);
  if (!p.fit.fitted) return outer;
  std::string text = "box fitted to the voxels (dropped";
  bool first = true;
  for (int side = 0; side < 6; ++side) {
    if (!(p.fit.dropped[side] > 0.f)) continue;
    char part[96];
    std::snprintf(part, sizeof part, "%s %s %.3g m: %s", first ? "" : ";", kSide[side], double(p.fit.dropped[side]),
                  slab_reason_text(p.fit.why[side]));
    text += part;
    first = false;
  }
  char tail[160];
  std::snprintf(tail, sizeof tail, "), instead of %llu probes %.3g m apart over the whole scene box",
                static_cast<unsigned long long>(p.unfitted_probes), double(p.unfitted_spacing));
  return text + tail + (outer.empty() ? "" : "; " + outer);
}

std::array<float, 3> probe_rest_position(const DdgiVolumeDesc& d, int32_t index) {
  const int32_t x = index % d.counts[0];
  const int32_t y = (index / d.counts[0]) % d.counts[1];
  const int32_t z = index / (d.counts[0] * d.counts[1]);
  return {d.grid_min[0] + d.spacing[0] * x, d.grid_min[1] + d.spacing[1] * y, d.grid_min[2] + d.spacing[2] * z};
}

float min_cell_size(const DdgiVolumeDesc& d) {
  float m = 0.f;
  for (int a = 0; a < 3; ++a)
    if (d.counts[a] > 1 && d.spacing[a] > 0.f && (m == 0.f || d.spacing[a] < m)) m = d.spacing[a];
  return m;
}

}  // namespace gibake
