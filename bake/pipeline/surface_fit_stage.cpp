// The surface fit stage (surface_fit_stage.h).
#include "bake/pipeline/surface_fit_stage.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>

#include "bake/ddgi/fit_gather.h"
#include "bake/pipeline/check_refine.h"
#include "bake/pipeline/devices.h"
#include "bake/preview/reconstruction_check.h"
#include "bake/run/arena.h"
#include "bake/trace/probe_field_cache.h"
#include "io/timer.h"
#include "kernels/ray_gen.h"
#include "kernels/vec.h"

namespace gibake {

namespace {

using kernels::float3;

constexpr uint64_t kFitSalt = 0x73757266666974ull;  // the fit's directions and paths, apart from the bake's rays

struct FitProbe {
  float3 position;
  float reach = 0.f;
  uint32_t volume = 0;
  float spacing = 0.f;  // its volume's largest
};

// The lit probes of every volume in file order, each with its volume's reach.
std::vector<FitProbe> fit_probes(const loader::BakeFile& file, float reach_spacings) {
  std::vector<FitProbe> out;
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i) {
    const loader::DdgiVolume& v = file.ddgi_volumes()[i];
    const float* sp = v.desc().spacing;
    const float spacing = std::max({sp[0], sp[1], sp[2]});
    for (uint32_t p = 0; p < v.probe_count(); ++p) {
      if (v.state(p) != GIBAKE_PROBE_ACTIVE) continue;
      const loader::Vec3 at = v.probe_position(p);
      out.push_back(FitProbe{float3{at[0], at[1], at[2]}, reach_spacings * spacing, uint32_t(i), spacing});
    }
  }
  return out;
}

// A surface point and the probe whose ray found it.
struct FoundPoint {
  VisibleSurface surface;
  uint32_t probe = 0;
};

// From each probe, `directions` rays (a Fibonacci set rotated per probe) to the first visible
// surface within its reach: the points, in probe and direction order.
std::vector<FoundPoint> surface_points(const BakeResult& run, const std::vector<FitProbe>& probes, uint32_t directions,
                                       uint64_t seed, const Context& ctx) {
  std::vector<VisibleSurface> slots(probes.size() * directions);
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] {
    tbb::parallel_for(size_t(0), probes.size(), [&](size_t i) {
      std::vector<float> dirs(size_t(directions) * 3);
      kernels::generate_probe_rays(seed, uint32_t(i), 0, directions, dirs.data());
      for (uint32_t k = 0; k < directions; ++k) {
        const float3 d{dirs[k * 3], dirs[k * 3 + 1], dirs[k * 3 + 2]};
        slots[i * directions + k] = visible_surface(*run.prepared, run.lod, probes[i].position, d, probes[i].reach);
      }
    });
  });
  std::vector<FoundPoint> points;
  for (size_t i = 0; i < slots.size(); ++i)
    if (slots[i].valid) points.push_back(FoundPoint{slots[i], uint32_t(i / directions)});
  return points;
}

// At most `max` of the points, spread evenly over them (every probe keeps its share).
std::vector<FoundPoint> thin_out(std::vector<FoundPoint> points, uint64_t max) {
  if (points.size() <= max) return points;
  std::vector<FoundPoint> kept;
  kept.reserve(size_t(max));
  for (uint64_t k = 0; k < max; ++k) kept.push_back(points[size_t(k * points.size() / max)]);
  return kept;
}

// Each sample's truth from its point's paths (fit_gather.h). `both`: the light holds both
// estimates; `fitted`: its ended paths were read in fitted probes.
void fill_light(std::vector<SurfaceFitSample>& samples, const std::vector<FoundPoint>& points,
                const std::vector<SurfaceLight>& light, const std::vector<FitProbe>& probes, bool both,
                bool fitted = false) {
  std::vector<FitPointLight> lum(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const SurfaceLight& l = light[i];
    const FitProbe& probe = probes[points[i].probe];
    const float at[3] = {probe.position.x, probe.position.y, probe.position.z};
    lum[i] = FitPointLight{luminance(l.irradiance), {l.half[0], l.half[1]},
                           luminance(l.probe_lit),  {l.probe_half[0], l.probe_half[1]},
                           points[i].probe,         fit_region(probe.volume, at, probe.spacing)};
  }
  const std::vector<FitTruth> truths = fit_truths(lum, both, fitted);
  for (size_t i = 0; i < points.size(); ++i) {
    samples[i].truth = float(truths[i].truth);
    samples[i].noise = float(truths[i].noise);
  }
}

// The side of the cubes over which the ended paths share a read of the probes: `share` of the
// file's finest probe spacing (0: none, every hit reads the probes).
float shared_read_cell(const loader::BakeFile& file, float share) {
  float finest = 0.f;
  for (const loader::DdgiVolume& v : file.ddgi_volumes())
    for (float s : v.desc().spacing)
      if (s > 0.f && std::isfinite(s)) finest = finest > 0.f ? std::min(finest, s) : s;
  return share > 0.f ? share * finest : 0.f;
}

// The probes `file` holds as the ended paths read them: through shared reads when `read_cell` > 0.
struct FieldReads {
  FieldReads(const loader::BakeFile& file, float read_cell, const Context& ctx)
      : direct(file),
        shared(direct, read_cell > 0.f ? read_cell : 1.f, CachedProbeField::table_bits_for(worker_count(ctx))),
        field(read_cell > 0.f ? static_cast<const ProbeField&>(shared) : direct) {}
  BakeFileProbeField direct;
  CachedProbeField shared;
  const ProbeField& field;
};

// The paths ended at their first hit in the fitted probes (SurfaceFitSettings::passes): the hits
// the CPU kept, else (a device traced them) the paths traced again and ended there. Only `light`'s
// ended estimates change. `shared`: whether the reads went through CachedProbeField.
Status end_in_fitted(const BakeRequest& r, const BakeResult& run, const std::vector<VisibleSurface>& surfaces,
                     uint64_t seed, float read_cell, const EndedPathHits& kept, std::vector<SurfaceLight>& light,
                     bool& shared, const Context& ctx) {
  const SurfaceFitSettings& s = r.ddgi_settings.fit;
  std::vector<uint8_t> bytes;
  GIBAKE_TRY(encode_baked_volumes(r, run, bytes));
  loader::BakeFile fitted;
  if (loader::Error e = fitted.open_borrowed(bytes.data(), bytes.size(), loader::LoadOptions{false, true}))
    return Status::error(ExitCode::RuntimeFailure, r.files.out, loader::error_code_name(e.code), e.message);
  const FieldReads reads(fitted, read_cell, ctx);
  if (kept.complete) {
    end_kept_paths(kept, reads.field, ctx, light);
    shared = reads.shared.used();
    return Status::ok();
  }
  std::unique_ptr<ReferencePathDevice> device = make_reference_path_device(run.gpu);
  std::vector<SurfaceLight> again;
  GIBAKE_TRY(trace_surface_irradiance(*run.prepared, run.lod, run.volumes[0].result.settings_json, surfaces, s.paths,
                                      seed, device.get(), ctx, again, &reads.field, true, s.roulette_depth));
  for (size_t i = 0; i < light.size(); ++i) {
    light[i].probe_lit = again[i].probe_lit;
    light[i].probe_half[0] = again[i].probe_half[0];
    light[i].probe_half[1] = again[i].probe_half[1];
  }
  shared = reads.shared.used();
  return Status::ok();
}

std::string shared_read_note(float cell) {
  char text[96];
  std::snprintf(text, sizeof text, ", the probes read once per %.3g m cube and normal", double(cell));
  return text;
}

// The fit's points (surface_points, thinned out to the fit's most), with the probes that found them.
struct FitPoints {
  std::vector<FitProbe> probes;
  std::vector<FoundPoint> points;
  std::vector<VisibleSurface> surfaces;   // where each point's paths start
  std::vector<SurfaceFitSample> samples;  // each point's place here, its light once traced
};

FitPoints find_fit_points(const loader::BakeFile& file, const BakeResult& run, const SurfaceFitSettings& s,
                          uint64_t seed, const Context& ctx) {
  FitPoints out;
  out.probes = fit_probes(file, s.reach);
  out.points = thin_out(surface_points(run, out.probes, s.directions, seed, ctx), s.max_samples);
  for (const FoundPoint& p : out.points) {
    out.surfaces.push_back(p.surface);
    out.samples.push_back(SurfaceFitSample{p.surface.p, p.surface.n});
  }
  return out;
}

// How the fit gathers its truths (SurfaceFitSettings::gather, ::passes).
struct FitRoute {
  bool gather_probes = false;  // its paths also end in the probes' light
  bool both = false;           // ... and it keeps both estimates
  // A second pass: the first fit reads the whole paths alone, and the paths are then ended in its
  // fitted probes. The CPU keeps their first hits for that, unread.
  bool again = false;
};

FitRoute fit_route(const SurfaceFitSettings& s) {
  FitRoute route;
  route.gather_probes = s.gather != FitGather::Paths;
  route.both = s.gather == FitGather::Both;
  route.again = route.both && s.passes > 1;
  return route;
}

// Every point's paths into `light`, and the fit's rows: they read no light, so while a device
// traces the paths the CPU builds them beside it. `reads`: the probes the paths end in, before the
// fit. Paths that only end in the probes are the CPU's; with both, a device ends them too where it
// can read the probes (trace_surface_irradiance). `traced_at`: `time` once the paths are traced
// (rows built after them count towards the solve).
Status trace_fit_paths(const BakeRequest& r, const BakeResult& run, const loader::BakeFile& file, const FitRoute& route,
                       const ProbeField& reads, uint64_t seed, const std::vector<DdgiResult*>& volumes,
                       const Context& ctx, FitPoints& fp, std::vector<SurfaceLight>& light, EndedPathHits& kept,
                       FitRows& rows, const Stopwatch& time, double& traced_at) {
  const SurfaceFitSettings& s = r.ddgi_settings.fit;
  std::unique_ptr<ReferencePathDevice> device = make_reference_path_device(run.gpu);
  std::future<FitRows> rows_beside;
  if (device) rows_beside = std::async(std::launch::async, [&] { return fit_rows(file, fp.samples, volumes, ctx); });
  const Status traced = trace_surface_irradiance(
      *run.prepared, run.lod, run.volumes[0].result.settings_json, fp.surfaces, s.paths, seed, device.get(), ctx, light,
      route.gather_probes ? &reads : nullptr, route.both, s.roulette_depth, route.again ? &kept : nullptr);
  traced_at = time.seconds();
  if (rows_beside.valid()) rows_beside.wait();  // it reads fp's samples
  GIBAKE_TRY(traced);
  rows = rows_beside.valid() ? rows_beside.get() : fit_rows(file, fp.samples, volumes, ctx);
  return Status::ok();
}

// The summary line of the fit: what it fitted, and from which points and paths.
std::string fit_note(const BakeResult& run, const SurfaceFitSettings& s, const FitRoute& route, size_t probes,
                     bool shared, float read_cell) {
  return surface_fit_summary(run.surface_fit) + " (" + std::to_string(s.directions) + " directions from each of " +
         std::to_string(probes) + " lit probes, " + std::to_string(s.paths) +
         (route.again  ? " paths a point, fitted to them, then again with each also ended at its first hit in the "
                         "fitted probes' light"
          : route.both ? " paths a point, each also ended at its first hit in the probes' light"
          : route.gather_probes ? " one-bounce paths a point lit by the probes"
                                : " paths a point") +
         (shared ? shared_read_note(read_cell) : std::string()) + ")";
}

}  // namespace

Status fit_surfaces(const BakeRequest& r, const Context& ctx, BakeResult& run) {
  const SurfaceFitSettings& s = r.ddgi_settings.fit;
  if (!s.enabled || r.shard || run.volumes.empty() || !run.prepared) return Status::ok();
  const Stopwatch time;
  std::vector<uint8_t> bytes;
  GIBAKE_TRY(encode_baked_volumes(r, run, bytes));
  loader::BakeFile file;
  // Probe-major tiles: the ended paths read the probes at scattered points (LoadOptions).
  if (loader::Error e = file.open_borrowed(bytes.data(), bytes.size(), loader::LoadOptions{false, true}))
    return Status::error(ExitCode::RuntimeFailure, r.files.out, loader::error_code_name(e.code), e.message);
  const uint64_t seed = r.ddgi_settings.seed ^ kFitSalt;
  FitPoints fp = find_fit_points(file, run, s, seed, ctx);
  std::vector<DdgiResult*> volumes;
  for (BakedVolume& v : run.volumes) volumes.push_back(&v.result);
  const double found = time.seconds();
  const FitRoute route = fit_route(s);
  const float read_cell = shared_read_cell(file, s.read_cell);
  const FieldReads reads(file, read_cell, ctx);  // the probes before fitting
  std::vector<SurfaceLight> light;
  EndedPathHits kept;
  FitRows rows;
  double traced = 0.0;
  GIBAKE_TRY(
      trace_fit_paths(r, run, file, route, reads.field, seed, volumes, ctx, fp, light, kept, rows, time, traced));
  fill_light(fp.samples, fp.points, light, fp.probes, route.both && !route.again);
  std::vector<std::vector<float>> baked;  // the atlases before the fit, for the second pass
  if (route.again)
    for (const DdgiResult* v : volumes) baked.push_back(v->irradiance_atlas);
  GIBAKE_TRY(fit_irradiance_atlases(file, fp.samples, rows, s, volumes, ctx, run.surface_fit));
  const double first_fit = time.seconds();
  bool shared = reads.shared.used();
  if (route.again) {
    GIBAKE_TRY(end_in_fitted(r, run, fp.surfaces, seed, read_cell, kept, light, shared, ctx));
    kept = EndedPathHits{};
    for (size_t i = 0; i < volumes.size(); ++i) volumes[i]->irradiance_atlas = std::move(baked[i]);
    fill_light(fp.samples, fp.points, light, fp.probes, route.both, true);
    GIBAKE_TRY(fit_irradiance_atlases(file, fp.samples, rows, s, volumes, ctx, run.surface_fit));
  }
  run.have_surface_fit = true;
  run.surface_fit.seconds = time.seconds();
  ctx.note(fit_note(run, s, route, fp.probes.size(), shared, read_cell));
  run.timings.emplace_back("surface fit (points)", found);
  run.timings.emplace_back("surface fit (paths)", traced - found);
  run.timings.emplace_back("surface fit (solve)", first_fit - traced);
  if (route.again) run.timings.emplace_back("surface fit (in the fitted probes)", run.surface_fit.seconds - first_fit);
  return Status::ok();
}

}  // namespace gibake
