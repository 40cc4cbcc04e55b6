// Irradiance atlases fitted to the surfaces they light (surface_fit.h).
#include "bake/ddgi/surface_fit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/ddgi/fit_solve.h"
#include "bake/run/arena.h"
#include "gibake/loader.hpp"
#include "io/timer.h"
#include "kernels/octahedral.h"
#include "kernels/vec.h"

namespace gibake {

namespace {

constexpr size_t kChunk = 8192;      // rows or texels a task; sums reduced chunk by chunk in order
constexpr float kHalfMax = 65504.f;  // float16's largest finite value

using kernels::luminance;

// For each texel of a tile (border included, row-major), the interior texel it holds: the border
// rule applied to the texels' own indices.
std::vector<int> tile_sources(int res) {
  const int side = res + 2;
  std::vector<float> index(size_t(side) * side, 0.f);
  for (int i = 0; i < side * side; ++i) index[size_t(i)] = float(i);
  kernels::oct_fill_border(index.data(), side, 1, 0, 0, res);
  std::vector<int> out(index.size());
  for (size_t i = 0; i < index.size(); ++i) out[i] = int(index[i]);
  return out;
}

using RawEntry = FitRows::Entry;

// A point's row: the sampler's weight of every texel it reads times the texel's luminance, summed
// over the volumes' shares as BakeFile::sample_ddgi sums them.
void point_row(const loader::BakeFile& file, const std::vector<const DdgiResult*>& volumes,
               const std::vector<int>& sources, const SurfaceFitSample& s, std::vector<RawEntry>& row) {
  row.clear();
  const loader::Vec3 p{s.p.x, s.p.y, s.p.z}, n{s.n.x, s.n.y, s.n.z};
  for (const loader::VolumeShare& share : file.ddgi_shares(p, n)) {
    const loader::DdgiVolume& v = file.ddgi_volumes()[share.volume];
    const DdgiResult& r = *volumes[share.volume];
    loader::ProbeWeight w[8];
    const uint32_t count = v.probe_weights(p, n, w);
    float sum = 0.f;
    for (uint32_t i = 0; i < count; ++i) sum += w[i].weight;
    if (!(sum > 0.f)) continue;
    const int side = kIrradianceTexels + 2;
    for (uint32_t i = 0; i < count; ++i) {
      loader::AtlasTexel texels[4];
      const uint32_t m = v.irradiance_texels(w[i].probe, n, texels);
      for (uint32_t k = 0; k < m; ++k) {
        const std::array<float, 4> t = v.irradiance_texel(texels[k].x, texels[k].y);
        const float a = share.share * (w[i].weight / sum) * texels[k].weight * luminance(t[0], t[1], t[2]);
        if (!(a > 0.f)) continue;
        const int lx = int(texels[k].x) % side, ly = int(texels[k].y) % side;
        const int src = sources[size_t(ly * side + lx)];
        const uint32_t x = texels[k].x - uint32_t(lx) + uint32_t(src % side);
        const uint32_t y = texels[k].y - uint32_t(ly) + uint32_t(src / side);
        row.push_back(RawEntry{share.volume, y * uint32_t(r.irradiance_width) + x, a});
      }
    }
  }
}

// An atlas place: a texel (y * width + x) or a probe's tile ((y / side) * tiles across + x / side).
struct AtlasPlace {
  uint32_t volume = 0;
  uint32_t index = 0;
};

// The fit's matrix: rows scaled by 1 / B_s (rhs_row E_s / B_s), one column per texel (its whole
// gain G + d) and one group per probe tile (G), numbered in the order points first read them; a
// texel pulled towards its tile's gain by lambda', a tile's gain towards 1 by lambda_probe.
struct FitSystem : SparseLeastSquares {
  std::vector<AtlasPlace> texels, tiles;  // per column, per group
  std::vector<double> truth;              // per row, luminance
};

Status check_layout(const loader::BakeFile& file, const std::vector<DdgiResult*>& volumes) {
  if (file.ddgi_volumes().size() != volumes.size())
    return Status::invalid("", "surface fit", "the encoded file and the bake hold different volumes");
  for (size_t v = 0; v < volumes.size(); ++v) {
    const DdgiResult& r = *volumes[v];
    const loader::DdgiVolume& lv = file.ddgi_volumes()[v];
    if (r.irradiance_atlas.empty() || !lv.has_irradiance()) continue;
    const std::array<uint32_t, 2> last = lv.tile_origin(lv.probe_count() - 1, kIrradianceTexels);
    if (lv.desc().irradiance_tile != uint32_t(kIrradianceTexels) || lv.desc().tile_border != 1 ||
        last[0] + kIrradianceTexels + 2 > uint32_t(r.irradiance_width) ||
        last[1] + kIrradianceTexels + 2 > uint32_t(r.irradiance_height))
      return Status::invalid("", "surface fit", "volume " + std::to_string(v) + "'s irradiance atlas layout differs");
  }
  return Status::ok();
}

// What a point's row is scaled by: its trust over its baked value B_s. A point whose baked or
// path-traced value is not a number, or whose baked value is not positive, stays out.
struct RowScale {
  double trust = 0.0, baked = 0.0;
  bool kept = false;
};

RowScale row_scale(const SurfaceFitSample& sample, const RawEntry* first, const RawEntry* last,
                   const SurfaceFitSettings& s) {
  RowScale r;
  for (const RawEntry* e = first; e != last; ++e) r.baked += e->a;
  const double truth = sample.truth;
  if (!(r.baked > 0.0) || !std::isfinite(r.baked) || !(truth >= 0.0) || !std::isfinite(truth)) return r;
  const double trusted = double(s.trusted_noise) * s.trusted_noise;
  const double noise = std::isfinite(sample.noise) ? std::max(0.0, double(sample.noise)) : 0.0;
  r.trust = std::sqrt(trusted / (noise + trusted));  // rows enter squared
  r.kept = true;
  return r;
}

// Numbers a kept row's texels and tiles in the order points first read them (new ones become
// columns and groups of the system) and writes each entry's column to `column`.
void number_row(const RawEntry* first, const RawEntry* last, const SurfaceFitSettings& s,
                const std::vector<const DdgiResult*>& volumes, std::vector<std::vector<int32_t>>& id,
                std::vector<std::vector<int32_t>>& tile_id, FitSystem& sys, uint32_t* column) {
  const uint32_t side = kIrradianceTexels + 2;
  for (const RawEntry* at = first; at != last; ++at, ++column) {
    const RawEntry& e = *at;
    const uint32_t width = uint32_t(volumes[e.volume]->irradiance_width);
    const uint32_t tile = (e.texel / width / side) * (width / side) + e.texel % width / side;
    int32_t& t = tile_id[e.volume][tile];
    if (t < 0) {
      t = int32_t(sys.tiles.size());
      sys.tiles.push_back(AtlasPlace{e.volume, tile});
      sys.group_prior.push_back(s.lambda_probe);
      sys.group_target.push_back(1.0);
    }
    int32_t& c = id[e.volume][e.texel];
    if (c < 0) {
      c = int32_t(sys.texels.size());
      sys.texels.push_back(AtlasPlace{e.volume, e.texel});
      sys.prior.push_back(texel_prior(s));
      sys.target.push_back(1.0);
      sys.group.push_back(t);
    }
    *column = uint32_t(c);
  }
}

// The rows, numbered texels and the transpose. Points whose baked or path-traced value is not a
// positive number stay out.
void build_system(const std::vector<SurfaceFitSample>& samples, const FitRows& rows, const SurfaceFitSettings& s,
                  const std::vector<DdgiResult*>& volumes, FitSystem& sys) {
  const std::vector<const DdgiResult*> results(volumes.begin(), volumes.end());
  std::vector<std::vector<int32_t>> id(volumes.size()), tile_id(volumes.size());
  for (size_t v = 0; v < volumes.size(); ++v) {
    const size_t w = size_t(volumes[v]->irradiance_width), h = size_t(volumes[v]->irradiance_height);
    id[v].assign(w * h, -1);
    tile_id[v].assign((w / (kIrradianceTexels + 2)) * (h / (kIrradianceTexels + 2)), -1);
  }
  const size_t n = samples.size();
  std::vector<RowScale> scales(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i < range.end(); ++i)
      scales[i] =
          row_scale(samples[i], rows.entries.data() + rows.start[i], rows.entries.data() + rows.start[i + 1], s);
  });
  // Numbered in point order (the columns' order is the points'), then the values written in parallel.
  std::vector<size_t> at(n, 0);  // each kept row's first entry in the system
  sys.row_start.push_back(0);
  for (size_t i = 0; i < n; ++i) {
    if (!scales[i].kept) continue;
    at[i] = sys.row_start.back();
    sys.row_start.push_back(at[i] + (rows.start[i + 1] - rows.start[i]));
    const double truth = samples[i].truth;
    sys.rhs_row.push_back(scales[i].trust * truth / scales[i].baked);
    sys.truth.push_back(truth);
  }
  sys.column.resize(sys.row_start.back());
  sys.value.resize(sys.row_start.back());
  for (size_t i = 0; i < n; ++i)
    if (scales[i].kept)
      number_row(rows.entries.data() + rows.start[i], rows.entries.data() + rows.start[i + 1], s, results, id, tile_id,
                 sys, &sys.column[at[i]]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i < range.end(); ++i) {
      if (!scales[i].kept) continue;
      for (size_t k = rows.start[i]; k < rows.start[i + 1]; ++k)
        sys.value[at[i] + (k - rows.start[i])] = float(scales[i].trust * rows.entries[k].a / scales[i].baked);
    }
  });
  index_columns(sys, sys.texels.size());
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto at =
      v.begin() + std::ptrdiff_t(std::min(v.size() - 1, size_t(std::floor(q * double(v.size() - 1) + 0.5))));
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

// Within 10% and the median of predicted / truth (`g`: each texel's gain) over the rows whose truth is
// above a thousandth of the mean (black against black says nothing, as the check leaves such patches out).
void ratio_figures(const FitSystem& sys, const std::vector<double>& g, double& within, double& median) {
  double mean = 0.0;
  for (double t : sys.truth) mean += t;
  mean = sys.truth.empty() ? 0.0 : mean / double(sys.truth.size());
  std::vector<double> all(sys.truth.size(), 0.0);  // each row's ratio, rows apart
  tbb::parallel_for(tbb::blocked_range<size_t>(0, all.size(), kChunk), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t r = range.begin(); r < range.end(); ++r) {
      double s = 0.0;
      for (size_t k = sys.row_start[r]; k < sys.row_start[r + 1]; ++k) s += double(sys.value[k]) * g[sys.column[k]];
      all[r] = s / sys.rhs_row[r];
    }
  });
  std::vector<double> ratios;
  size_t in = 0;
  for (size_t r = 0; r < sys.truth.size(); ++r) {
    if (!(sys.truth[r] > 1e-3 * mean)) continue;
    ratios.push_back(all[r]);
    in += std::fabs(all[r] - 1.0) <= 0.1;
  }
  within = ratios.empty() ? 0.0 : double(in) / double(ratios.size());
  median = quantile(ratios, 0.5);
}

// The gains into the atlases: interior texels scaled, then the borders of every tile a point read
// (the groups are those tiles).
void apply_gains(const FitSystem& sys, const std::vector<double>& g, const std::vector<DdgiResult*>& volumes) {
  const int side = kIrradianceTexels + 2;
  for (size_t c = 0; c < sys.texels.size(); ++c) {
    const AtlasPlace& col = sys.texels[c];
    float* texel = &volumes[col.volume]->irradiance_atlas[size_t(col.index) * 4];
    // A gain never takes a texel past float16's largest value: the file keeps the half-size
    // atlas it had (--atlas-format auto), for a few texels of the brightest indirect light.
    const float top = std::max({texel[0], texel[1], texel[2]});
    const float gain = top <= kHalfMax && top * float(g[c]) > kHalfMax ? kHalfMax / top : float(g[c]);
    for (int k = 0; k < 3; ++k) texel[k] = top <= kHalfMax ? std::min(texel[k] * gain, kHalfMax) : texel[k] * gain;
  }
  for (const AtlasPlace& col : sys.tiles) {
    DdgiResult& r = *volumes[col.volume];
    const int tiles_x = r.irradiance_width / side;
    kernels::oct_fill_border(r.irradiance_atlas.data(), r.irradiance_width, 4,
                             int(col.index % uint32_t(tiles_x)) * side, int(col.index / uint32_t(tiles_x)) * side,
                             kIrradianceTexels);
  }
}

// Each texel's gain (its probe's and its own) from the solution, clamped.
std::vector<double> clamped_gains(const std::vector<double>& g, const SurfaceFitSettings& s) {
  std::vector<double> gain(g.size(), 1.0);
  for (size_t c = 0; c < g.size(); ++c)
    gain[c] = std::clamp(std::isfinite(g[c]) ? g[c] : 1.0, double(s.min_gain), double(s.max_gain));
  return gain;
}

}  // namespace

double texel_prior(const SurfaceFitSettings& s) {
  return double(s.lambda) * double(kLambdaPaths) / double(std::max<uint32_t>(1, s.paths));
}

FitRows fit_rows(const loader::BakeFile& file, const std::vector<SurfaceFitSample>& points,
                 const std::vector<DdgiResult*>& volumes, const Context& ctx) {
  const std::vector<const DdgiResult*> results(volumes.begin(), volumes.end());
  const std::vector<int> sources = tile_sources(kIrradianceTexels);
  FitRows out;
  out.start.push_back(0);
  // A chunk of points at a time (each point's own row is the largest transient): rows made in
  // parallel, then appended in point order.
  constexpr size_t kRowChunk = 65536;
  std::vector<std::vector<RawEntry>> rows;
  std::vector<size_t> at;
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] {
    for (size_t first = 0; first < points.size(); first += kRowChunk) {
      const size_t n = std::min(kRowChunk, points.size() - first);
      rows.assign(n, {});
      tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i < range.end(); ++i)
          point_row(file, results, sources, points[first + i], rows[i]);
      });
      at.assign(n, 0);
      for (size_t i = 0; i < n; ++i) {
        at[i] = out.start.back();
        out.start.push_back(at[i] + rows[i].size());
      }
      out.entries.resize(out.start.back());
      tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i < range.end(); ++i)
          std::copy(rows[i].begin(), rows[i].end(), out.entries.data() + at[i]);
      });
    }
  });
  return out;
}

Status fit_irradiance_atlases(const loader::BakeFile& file, const std::vector<SurfaceFitSample>& samples,
                              const SurfaceFitSettings& s, const std::vector<DdgiResult*>& volumes, const Context& ctx,
                              SurfaceFitReport& report) {
  GIBAKE_TRY(check_layout(file, volumes));  // before the rows read the results' atlases
  return fit_irradiance_atlases(file, samples, fit_rows(file, samples, volumes, ctx), s, volumes, ctx, report);
}

Status fit_irradiance_atlases(const loader::BakeFile& file, const std::vector<SurfaceFitSample>& samples,
                              const FitRows& rows, const SurfaceFitSettings& s, const std::vector<DdgiResult*>& volumes,
                              const Context& ctx, SurfaceFitReport& report) {
  report = SurfaceFitReport{};
  const Stopwatch time;
  GIBAKE_TRY(check_layout(file, volumes));
  if (rows.start.size() != samples.size() + 1)
    return Status::invalid("", "surface fit", "the rows were built for other points");
  report.samples = samples.size();
  FitSystem sys;
  std::vector<double> g;
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] {
    build_system(samples, rows, s, volumes, sys);
    report.iterations = solve_least_squares(sys, g);
    if (s.relative_to_fit > 0.f) {  // SurfaceFitSettings::relative_to_fit
      scale_rows_by_solution(sys, clamped_gains(g, s), s.relative_to_fit, s.min_gain, s.max_gain);
      report.iterations += solve_least_squares(sys, g);
    }
  });
  const std::vector<double> gain = clamped_gains(g, s), ones(g.size(), 1.0);
  report.used = sys.rhs_row.size();
  report.texels = gain.size();
  arena->execute([&] {
    ratio_figures(sys, ones, report.within_before, report.median_before);
    ratio_figures(sys, gain, report.within_after, report.median_after);
  });
  report.gain_p10 = quantile(gain, 0.1);
  report.gain_median = quantile(gain, 0.5);
  report.gain_p90 = quantile(gain, 0.9);
  apply_gains(sys, gain, volumes);
  report.seconds = time.seconds();
  return Status::ok();
}

const char* fit_gather_name(FitGather gather) {
  return gather == FitGather::Probes ? "probes" : gather == FitGather::Both ? "both" : "paths";
}

bool parse_fit_gather(const std::string& text, FitGather& out) {
  if (text == "probes")
    out = FitGather::Probes;
  else if (text == "paths")
    out = FitGather::Paths;
  else if (text == "both")
    out = FitGather::Both;
  else
    return false;
  return true;
}

std::string surface_fit_summary(const SurfaceFitReport& r) {
  char line[512];
  // Nothing read light: ratios of nothing must not read as figures.
  if (r.used == 0 || r.texels == 0) {
    std::snprintf(line, sizeof line,
                  "surface fit: skipped: none of the %llu surface points near the probes reads light from them, so "
                  "nothing was fitted; %.2f s",
                  static_cast<unsigned long long>(r.samples), r.seconds);
    return line;
  }
  std::snprintf(line, sizeof line,
                "surface fit: %llu texels fitted to %llu path-traced surface points (%llu read light); on those "
                "points %.0f%% -> %.0f%% within 10%%, median %.2f -> %.2f; gains p10 %.2f, median %.2f, p90 %.2f; "
                "%d iterations, %.2f s",
                static_cast<unsigned long long>(r.texels), static_cast<unsigned long long>(r.samples),
                static_cast<unsigned long long>(r.used), 100.0 * r.within_before, 100.0 * r.within_after,
                r.median_before, r.median_after, r.gain_p10, r.gain_median, r.gain_p90, r.iterations, r.seconds);
  return line;
}

}  // namespace gibake
