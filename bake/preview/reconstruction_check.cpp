#include "bake/preview/reconstruction_check.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "bake/preview/check_second_pass.h"
#include "bake/run/arena.h"
#include "bake/scene/emitters.h"
#include "bake/scene/lights.h"
#include "bake/scene/material.h"
#include "bake/trace/path_gather.h"
#include "io/timer.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"
#include "kernels/vec.h"

namespace gibake {
using kernels::float3;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kPickAttempts = 16;  // probe-view rays tried per point before giving it up
constexpr uint64_t kPickSalt = 0x7265636f6e706b31ull, kPathSalt = 0x7265636f6e707468ull;
constexpr uint64_t kSecondPassSalt = 0x7365636f6e64ull;  // the second pass's paths, apart from the first's

using kernels::luminance;

// Nearest-rank quantile of sorted values.
double quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const size_t i = size_t(std::floor(q * double(sorted.size() - 1) + 0.5));
  return sorted[std::min(i, sorted.size() - 1)];
}

// A surface point as a viewer sees it: position, shading normal and geometric normal facing the
// viewer, albedo and emission; `valid` false when the ray missed or met the inside of a
// single-sided surface.
struct SurfacePoint {
  bool valid = false;
  float3 p, n, ng, albedo, emission;
};

SurfacePoint surface_at(const PreparedScene& prepared, const TextureLod& lod, const float3& org, const float3& dir,
                        float footprint_per_metre, float tfar = kInf) {
  SurfacePoint sp;
  const TraceHit hit = prepared.intersect(org, dir, 0.f, tfar);
  if (hit.t <= 0.f) return sp;
  const Scene& scene = prepared.scene();
  if (!hit.front && !hit_material(scene, hit).double_sided) return sp;
  sp.ng = hit.front ? hit.ng : -hit.ng;
  sp.p = org + dir * hit.t;
  const SurfaceSample surf =
      hit_surface(scene, hit, TextureFootprint{&lod, footprint_per_metre * hit.t, kernels::dot(dir, sp.ng)});
  sp.n = kernels::dot(surf.normal, surf.normal) == 0.f ? sp.ng : surf.normal;
  if (kernels::dot(sp.n, sp.ng) < 0.f) sp.n = -sp.n;
  sp.albedo = surf.albedo;
  sp.emission = surf.emission;
  sp.valid = true;
  return sp;
}

}  // namespace

RatioDistribution ratio_stats(std::vector<double> ratios, double within) {
  RatioDistribution s;
  if (ratios.empty()) return s;
  size_t in = 0;
  std::vector<double> errors;
  errors.reserve(ratios.size());
  for (double r : ratios) {
    in += std::fabs(r - 1.0) <= within + 1e-12;
    errors.push_back(std::fabs(r - 1.0));
  }
  std::sort(ratios.begin(), ratios.end());
  std::sort(errors.begin(), errors.end());
  s.within = double(in) / double(ratios.size());
  s.p10 = quantile(ratios, 0.1);
  s.median = quantile(ratios, 0.5);
  s.p90 = quantile(ratios, 0.9);
  s.p90_error = quantile(errors, 0.9);
  return s;
}

// The active probes' positions (the probe-view points start there), of every volume read.
std::vector<float3> active_probes(const DdgiReader& ddgi) {
  std::vector<float3> out;
  for (const loader::DdgiVolume* volume : ddgi.volumes())
    for (uint32_t p = 0; p < volume->probe_count(); ++p) {
      if (volume->state(p) == GIBAKE_PROBE_INACTIVE) continue;
      const auto at = volume->probe_position(p);
      out.push_back(float3{at[0], at[1], at[2]});
    }
  return out;
}

namespace {

// The ratios over the patches above the floor, and the reference noise.
// The mean over the patches with points of their mean reference luminance.
double mean_reference(const std::vector<ReconstructionPatch>& patches) {
  double sum = 0.0;
  uint32_t n = 0;
  for (const ReconstructionPatch& p : patches) {
    if (p.points == 0) continue;
    ++n;
    sum += p.reference / float(p.points);
  }
  return n ? sum / n : 0.0;
}

// Whether a patch counts in the ratios: lit, and not below the floor (black shadow against black
// shadow says nothing).
bool counted_patch(const ReconstructionPatch& p, double mean_ref, const ReconstructionSettings& s) {
  return p.points > 0 && p.reference / float(p.points) > s.floor_fraction * mean_ref && p.reference > 0.f;
}

void summarize(const std::vector<ReconstructionPatch>& patches, const std::vector<uint64_t>& rays,
               const ReconstructionSettings& s, ReconstructionError& out) {
  for (size_t i = 0; i < patches.size(); ++i) {
    out.rays += rays[i];
    if (patches[i].points == 0) continue;
    ++out.patches;
    out.samples.push_back(patches[i]);
  }
  const double mean_ref = mean_reference(patches);
  std::vector<double> shaded, indirect, noise;
  for (const ReconstructionPatch& p : out.samples) {
    if (!counted_patch(p, mean_ref, s)) continue;
    shaded.push_back(double(p.baked) / p.reference);
    noise.push_back(double(p.reference_stderr) / p.reference);
    if (p.indirect_reference > 0.f) indirect.push_back(double(p.indirect_baked) / p.indirect_reference);
  }
  out.counted = uint32_t(shaded.size());
  out.shaded = ratio_stats(shaded, s.within);
  out.indirect = ratio_stats(indirect, s.within);
  std::sort(noise.begin(), noise.end());
  out.reference_noise = quantile(noise, 0.5);
}

constexpr int kPatchSide = 4;                  // points per patch side
constexpr float kPatchAngle = 2.5f * kernels::kPi / 180.f;  // probe-view patch width

// The points of patch `index`: 4x4 jittered pixel positions in one 8x8 block of the camera's view
// (blocks picked evenly through the image), or a 4x4 grid of directions kPatchAngle across around a
// random direction from a random active probe (retried until its centre meets a visible surface).
std::vector<SurfacePoint> pick_patch(const PreparedScene& prepared, const TextureLod& lod, const ReconstructionSettings& s,
                                     const std::vector<float3>& probes, uint32_t index, uint64_t& rays) {
  std::vector<SurfacePoint> out;
  if (!s.cameras.empty()) {
    const uint32_t views = uint32_t(s.cameras.size());
    const PreviewCamera& cam = s.cameras[index % views];
    const uint32_t bx = std::max(1, s.width / 8), by = std::max(1, s.height / 8), blocks = bx * by;
    // A camera's k-th patch takes block (k x golden ratio) mod blocks: evenly spread, no two alike
    // while k < blocks.
    const uint32_t block = uint32_t(std::fmod(double(index / views) * 0.6180339887498949 * blocks, double(blocks)));
    for (int j = 0; j < kPatchSide * kPatchSide; ++j) {
      const uint64_t key = kernels::rng_hash(s.seed, index, uint64_t(j), kPickSalt);
      const float px = float((block % bx) * 8) + 2.f * (float(j % kPatchSide) + kernels::rng_uniform(key, 0));
      const float py = float((block / bx) * 8) + 2.f * (float(j / kPatchSide) + kernels::rng_uniform(key, 1));
      ++rays;
      out.push_back(
          surface_at(prepared, lod, cam.eye, cam.ray(px, py, s.width, s.height), 2.f * cam.tan_half / float(s.height)));
    }
    return out;
  }
  for (int attempt = 0; attempt < kPickAttempts && !probes.empty(); ++attempt) {
    const uint64_t key = kernels::rng_hash(s.seed, index, uint64_t(attempt), kPickSalt);
    const float3 eye = probes[std::min(probes.size() - 1, size_t(kernels::rng_uniform(key, 0) * float(probes.size())))];
    const float z = 1.f - 2.f * kernels::rng_uniform(key, 1), phi = 2.f * kernels::kPi * kernels::rng_uniform(key, 2);
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    const float3 d{r * std::cos(phi), r * std::sin(phi), z};
    const float3 helper = std::fabs(d.y) < 0.9f ? float3{0.f, 1.f, 0.f} : float3{1.f, 0.f, 0.f};
    const float3 right = kernels::normalize(kernels::cross(helper, d)), up = kernels::cross(d, right);
    ++rays;
    if (!surface_at(prepared, lod, eye, d, 0.f).valid) continue;
    const float step = std::tan(kPatchAngle) / float(kPatchSide);
    for (int j = 0; j < kPatchSide * kPatchSide; ++j) {
      const float ox = (float(j % kPatchSide) + 0.5f - 0.5f * kPatchSide) * step;
      const float oy = (float(j / kPatchSide) + 0.5f - 0.5f * kPatchSide) * step;
      ++rays;
      out.push_back(surface_at(prepared, lod, eye, kernels::normalize(d + right * ox + up * oy), 0.f));
    }
    return out;
  }
  return out;
}

// Path r of a point's reference: a stratified cosine-weighted direction (m x m jittered strata, the
// rest unstratified: every ray is still distributed by cos/pi, so the mean stays unbiased, and sunlit
// patches seen from shadow, most of the variance, are sampled evenly), the key of its random
// numbers and its half of a checkerboard of the strata (the noise is read from the two halves).
// `traced` false: below the geometric surface, no light from there.
struct ReferencePath {
  float3 dir;
  uint64_t key = 0;
  int half = 0;
  bool traced = false;
};

ReferencePath reference_path(const SurfacePoint& sp, uint32_t rays, uint64_t point_key, uint32_t r) {
  const uint32_t m = uint32_t(std::sqrt(double(rays)));
  const uint64_t key = kernels::rng_hash(point_key, r, 0, kPathSalt);
  float u1 = kernels::rng_uniform(key, 0), u2 = kernels::rng_uniform(key, 1);
  ReferencePath out;
  out.half = int(r & 1u);
  if (r < m * m) {
    u1 = (float(r % m) + u1) / float(m);
    u2 = (float(r / m) + u2) / float(m);
    out.half = int((r % m + r / m) & 1u);
  }
  out.dir = kernels::sample_cosine_hemisphere(sp.n, std::min(u1, 0.99999994f), std::min(u2, 0.99999994f));
  out.traced = kernels::dot(out.dir, sp.ng) > 0.f;
  out.key = kernels::rng_hash(key, 1, 0, 0);  // trace_radiance's
  return out;
}

// One visible point of a patch: where it is, its paths' sums and its direct light.
struct PointSums {
  SurfacePoint sp;
  float3 origin{};   // of its paths and shadow rays: offset off the surface
  uint64_t key = 0;  // rng_hash(seed, patch, point index among the patch's 16)
  uint32_t rays = 0;  // its paths
  float3 sum{}, direct{};
  double half_lum[2] = {0.0, 0.0};
  uint32_t half_count[2] = {0, 0};
  TraceCounters tc{};
  // The same paths ended at their first hit in a probe field (trace_surface_irradiance's both).
  float3 ended_sum{};
  double ended_half_lum[2] = {0.0, 0.0};
};

// A point's sums started over for `rays` paths keyed by `key`; its direct light kept.
PointSums restarted(const PointSums& pt, uint64_t key, uint32_t rays) {
  PointSums out{pt.sp, pt.origin, key, rays};
  out.direct = pt.direct;
  return out;
}

// What trace_point sums from each path: the path as path.probe_field says (into `sum`), or, with a
// probe field, also or only the path ended at its first hit (into `ended_sum`; only: the paths were
// traced whole elsewhere, on a device).
enum class EndedPaths { None, Also, Only };

// The point's paths traced on the CPU, their radiance summed in path order. Path r is paired with
// emitter sample r of a shifted lattice over the point's paths (trace_surface_radiance). With
// EndedPaths::Also the probe field is read for all the point's paths after they are traced
// (EndedLight), and their ended light summed in path order; with `keep` (and Also) they are kept
// instead, unread (bake/trace/kept_hits.h).
void trace_point(const PathSetup& path, PointSums& pt, EndedPaths ended_paths = EndedPaths::None,
                 EndedPathHits::Point* keep = nullptr) {
  const uint64_t light_shift = kernels::rng_hash(pt.key, kernels::kProbeLightShiftRay, 0, kPathSalt);
  std::vector<EndedLight> deferred(ended_paths == EndedPaths::Also ? pt.rays : 0);
  std::vector<uint8_t> halves(deferred.size());
  for (uint32_t r = 0; r < pt.rays; ++r) {
    const ReferencePath rp = reference_path(pt.sp, pt.rays, pt.key, r);
    float u[3];
    kernels::probe_light_uniforms(light_shift, r, pt.rays, u);
    if (ended_paths == EndedPaths::Only) {
      const float3 ended =
          trace_surface_radiance(path, pt.origin, pt.sp.n, pt.sp.ng, rp.dir, rp.traced, u, rp.key, pt.tc);
      pt.ended_sum += ended;
      pt.ended_half_lum[rp.half] += luminance(ended);
      continue;
    }
    ++pt.half_count[rp.half];
    const float3 l =
        ended_paths == EndedPaths::Also
            ? trace_surface_radiance_ended(path, pt.origin, pt.sp.n, pt.sp.ng, rp.dir, rp.traced, u, rp.key, pt.tc,
                                           deferred[r])
            : trace_surface_radiance(path, pt.origin, pt.sp.n, pt.sp.ng, rp.dir, rp.traced, u, rp.key, pt.tc);
    pt.sum += l;
    pt.half_lum[rp.half] += luminance(l);
    if (!deferred.empty()) halves[r] = uint8_t(rp.half);
  }
  if (keep && ended_paths == EndedPaths::Also) return keep_ended_paths(deferred, halves, pt.half_count, *keep);
  for (size_t r = 0; r < deferred.size(); ++r) {
    const float3 ended = deferred[r].resolve(path.probe_field);
    pt.ended_sum += ended;
    pt.ended_half_lum[halves[r]] += luminance(ended);
  }
}

void direct_light(const PathSetup& path, PointSums& pt) {
  pt.direct =
      shade_punctual(path.trace, pt.origin, pt.sp.n, pt.sp.ng, pt.sp.albedo, pt.sp.emission, 0.f, pt.tc, nullptr);
}

// A point's sums added to its patch (in point order); what the baked half reads is kept in `kept`.
void add_point(const PointSums& pt, ReconstructionPatch& patch, double& variance,
               ReconstructionReference::Point& kept) {
  const SurfacePoint& sp = pt.sp;
  const float3 e_ref = pt.sum * (kernels::kPi / float(pt.rays));  // a traced point has paths
  if (patch.points++ == 0) {
    patch.position = {sp.p.x, sp.p.y, sp.p.z};
    patch.normal = {sp.n.x, sp.n.y, sp.n.z};
  }
  patch.reference += luminance(pt.direct + sp.albedo * e_ref * (1.f / kernels::kPi));
  patch.indirect_reference += luminance(e_ref);
  kept = {sp.p, sp.n, sp.albedo, pt.direct};
  // The two halves' means differ by about twice the standard error of the whole mean.
  const double a = pt.half_count[0] ? pt.half_lum[0] / pt.half_count[0] : 0.0;
  const double b = pt.half_count[1] ? pt.half_lum[1] / pt.half_count[1] : 0.0;
  const double se = double(luminance(sp.albedo)) * 0.5 * std::fabs(a - b);
  variance += se * se;
}

// The sums one device trace returned for a point.
void take_device_sums(const ReferencePointSums& o, bool ended_too, PointSums& pt) {
  pt.sum = o.sum;
  pt.half_lum[0] = o.half_lum[0];
  pt.half_lum[1] = o.half_lum[1];
  pt.half_count[0] = o.half_count[0];
  pt.half_count[1] = o.half_count[1];
  pt.tc.rays += o.traced;  // trace_radiance's count: each path's first ray
  pt.tc.shadow_rays += o.shadow_rays;
  pt.tc.bounce_rays += o.bounce_rays;
  if (!ended_too) return;
  pt.ended_sum = o.ended_sum;
  pt.ended_half_lum[0] = o.ended_half_lum[0];
  pt.ended_half_lum[1] = o.ended_half_lum[1];
}

// Every point's paths on `device`: the points of each path count together (a trace takes one count),
// in blocks of whole points that fit one of its traces; with `ended_too` (the device ends them in a
// probe field: end_paths_in) their ended sums too. Points without paths are left as they are.
Status trace_points_on_device(ReferencePathDevice& device, const PathSetup& path, std::vector<PointSums*>& points,
                              bool ended_too) {
  ReferencePathParams params;
  params.salt = kPathSalt;
  params.bounces = path.bounces;
  params.roulette_depth = path.roulette_depth;
  params.cone_spread = path.trace.cone_spread;
  params.shadow_bias = path.trace.shadow_bias;
  std::map<uint32_t, std::vector<PointSums*>> by_rays;
  for (PointSums* pt : points)
    if (pt->rays > 0) by_rays[pt->rays].push_back(pt);
  std::vector<ReferencePoint> block;
  std::vector<ReferencePointSums> out;
  for (auto& [rays, group] : by_rays) {
    params.rays = rays;
    const size_t per_block = std::max<size_t>(1, size_t(device.max_paths() / rays));
    for (size_t first = 0; first < group.size(); first += per_block) {
      const size_t n = std::min(per_block, group.size() - first);
      block.resize(n);
      for (size_t i = 0; i < n; ++i) {
        const PointSums& pt = *group[first + i];
        block[i] = {pt.origin, pt.sp.n, pt.sp.ng, pt.key};
      }
      GIBAKE_TRY(device.trace(block, params, out));
      if (out.size() != n)
        return Status::error(ExitCode::RuntimeFailure, "", "reconstruction check",
                             "the device returned too few points");
      for (size_t i = 0; i < n; ++i) take_device_sums(out[i], ended_too, *group[first + i]);
    }
  }
  return Status::ok();
}

// The reference's path tracer: converged paths (s.bounces, s.roulette_depth) with full-resolution
// texels at every vertex: the reference is the truth, and a filtered lookup is one of the bake's
// shortcuts (its probe rays read their cones' footprints).
PathSetup reference_path_setup(const PreparedScene& prepared, const TextureLod& lod,
                               const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                               const EmitterTable& emitters, const ReconstructionSettings& s) {
  PathSetup path = make_path_setup(prepared, lights, sky, emitters, s.seed, s.bounces);
  path.trace.lod = &lod;
  path.trace.cone_spread = 0.f;
  path.roulette_depth = s.roulette_depth;
  return path;
}

// The points' paths on `device` when there is one. A failure is no reason to fail a bake: the
// points' sums start over, `device` becomes null (the CPU traces them) and the failure is returned
// for a warning.
Status paths_on_device(ReferencePathDevice*& device, const PathSetup& path, std::vector<PointSums*>& points,
                       bool ended_too = false) {
  if (!device) return Status::ok();
  Status traced = trace_points_on_device(*device, path, points, ended_too);
  if (!traced) {
    for (PointSums* pt : points) *pt = restarted(*pt, pt->key, pt->rays);
    device = nullptr;
  }
  return traced;
}

// The paths of the patches' points (`only`: those patches; null: all) on `device` when there is
// one, else on the CPU, and with `direct` each point's direct light. A device that fails becomes
// null (the CPU traces) and its failure is returned for a warning.
Status trace_patches(ReferencePathDevice*& device, const PathSetup& path, std::vector<std::vector<PointSums>>& sums,
                     bool direct, const std::vector<uint32_t>* only = nullptr) {
  std::vector<PointSums*> all;
  for (size_t k = 0; k < (only ? only->size() : sums.size()); ++k)
    for (PointSums& pt : sums[only ? (*only)[k] : k]) all.push_back(&pt);
  const Status traced = paths_on_device(device, path, all);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, all.size(), 1),
      [&](const tbb::blocked_range<size_t>& range) {
        for (size_t k = range.begin(); k < range.end(); ++k) {
          if (!device) trace_point(path, *all[k]);
          if (direct) direct_light(path, *all[k]);
        }
      },
      tbb::simple_partitioner());
  return traced;
}

// Each patch's reference summed over its points in point order (`only`: those patches; null: all),
// with the rays its points' sums counted.
void sum_patches(const std::vector<std::vector<PointSums>>& sums, ReconstructionReference& out,
                 const std::vector<uint32_t>* only = nullptr) {
  tbb::parallel_for(size_t(0), only ? only->size() : sums.size(), [&](size_t k) {
    const size_t i = only ? (*only)[k] : k;
    ReconstructionPatch& patch = out.patches[i];
    patch = ReconstructionPatch{};
    double variance = 0.0;
    TraceCounters tc;
    out.points[i].resize(sums[i].size());
    for (size_t j = 0; j < sums[i].size(); ++j) {
      add_point(sums[i][j], patch, variance, out.points[i][j]);
      tc.rays += sums[i][j].tc.rays;
      tc.shadow_rays += sums[i][j].tc.shadow_rays;
      tc.bounce_rays += sums[i][j].tc.bounce_rays;
    }
    out.rays[i] += tc.rays + tc.shadow_rays + tc.bounce_rays;
    patch.reference_stderr = float(std::sqrt(variance));
  });
}

}  // namespace

Status trace_reconstruction_reference(const PreparedScene& prepared, const TextureLod& lod,
                                      const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                                      const std::vector<float3>& probes, const ReconstructionSettings& s,
                                      const Context& ctx, ReconstructionReference& out) {
  out = ReconstructionReference{};
  if (s.patches < 1 || s.patches > (1u << 20))
    return Status::error(ExitCode::BadArguments, "", "--check-patches", "must be between 1 and 1048576");
  if (s.rays < 1 || s.rays > (1u << 16))
    return Status::error(ExitCode::BadArguments, "", "--check-rays", "must be between 1 and 65536");
  const auto t0 = Clock::now();
  const EmitterTable emitters(prepared.scene());
  const PathSetup path = reference_path_setup(prepared, lod, lights, sky, emitters, s);
  out.probes = probes;
  out.patches.assign(s.patches, ReconstructionPatch{});
  out.points.assign(s.patches, {});
  out.rays.assign(s.patches, 0);
  // Patches first, then their points' paths point by point (a patch's 16 points x rays paths are
  // too coarse a task to balance), then each patch summed in point order: the same sums, bit for
  // bit, as tracing patch after patch.
  std::vector<std::vector<PointSums>> sums(s.patches);
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  ReferencePathDevice* device = s.device && s.device->lights_match(lights, sky) ? s.device : nullptr;
  Status traced;
  arena->execute([&] {
    tbb::parallel_for(uint32_t(0), s.patches, [&](uint32_t i) {
      const std::vector<SurfacePoint> points = pick_patch(prepared, lod, s, probes, i, out.rays[i]);
      for (size_t j = 0; j < points.size(); ++j)
        if (points[j].valid)
          sums[i].push_back(PointSums{points[j], offset_origin(path.trace, points[j].p, points[j].ng),
                                      kernels::rng_hash(s.seed, i, j, kPathSalt), s.rays});
    });
    traced = trace_patches(device, path, sums, true);
    sum_patches(sums, out);
    // The second pass: the noisiest patches' points traced again with more paths (their own, new
    // ones: the first pass only chose how many).
    // Patches the ratios leave out (below the floor) take none.
    std::vector<PatchNoise> noise(s.patches);
    const double mean_ref = mean_reference(out.patches);
    for (uint32_t i = 0; i < s.patches; ++i) {
      const ReconstructionPatch& p = out.patches[i];
      noise[i].points = uint32_t(sums[i].size());
      if (counted_patch(p, mean_ref, s) && std::isfinite(p.reference_stderr))
        noise[i].noise = double(p.reference_stderr) / p.reference;
    }
    const std::vector<uint32_t> more = second_pass_rays(noise, s.rays, s.target_noise, s.ray_budget,
                                                        default_budget_factor(device != nullptr, !s.cameras.empty()));
    std::vector<uint32_t> again;
    for (uint32_t i = 0; i < s.patches; ++i) {
      if (more[i] == 0) continue;
      again.push_back(i);
      for (size_t j = 0; j < sums[i].size(); ++j) {
        PointSums& pt = sums[i][j];
        pt = restarted(pt, kernels::rng_hash(s.seed ^ kSecondPassSalt, i, j, kPathSalt), more[i]);
      }
      out.retraced_rays = std::max(out.retraced_rays, more[i]);
    }
    out.retraced = uint32_t(again.size());
    if (again.empty()) return;
    const Status second = trace_patches(device, path, sums, false, &again);
    if (!second) traced = second;
    sum_patches(sums, out, &again);
  });
  if (!traced)
    ctx.warning("reconstruction check: the reference paths failed on the device (" + traced.message() +
                "); traced on the CPU instead");
  out.device = device ? device->name() : std::string();
  out.seconds = seconds_since(t0);
  return Status::ok();
}

void finish_reconstruction(const ReconstructionReference& reference, const DdgiReader& ddgi,
                           const ReconstructionSettings& s, ReconstructionError& out) {
  out = ReconstructionError{};
  const auto t0 = Clock::now();
  std::vector<ReconstructionPatch> patches = reference.patches;
  tbb::parallel_for(size_t(0), patches.size(), [&](size_t i) {
    for (const ReconstructionReference::Point& pt : reference.points[i]) {  // in the reference's order
      const loader::Rgb e = ddgi.sample({pt.p.x, pt.p.y, pt.p.z}, {pt.n.x, pt.n.y, pt.n.z}, s.sample);
      const float3 e_baked{e[0], e[1], e[2]};
      patches[i].baked += luminance(pt.direct + pt.albedo * e_baked * (1.f / kernels::kPi));
      patches[i].indirect_baked += luminance(e_baked);
    }
  });
  summarize(patches, reference.rays, s, out);
  out.retraced = reference.retraced;
  out.retraced_rays = reference.retraced_rays;
  out.source = s.cameras.empty()       ? "probes' view"
               : s.cameras.size() == 1 ? "camera"
                                       : std::to_string(s.cameras.size()) + " cameras";
  out.seconds = reference.seconds + seconds_since(t0);
}

Status measure_reconstruction(const PreparedScene& prepared, const TextureLod& lod,
                              const std::vector<kernels::ShadeLight>& lights, const Sky& sky, const DdgiReader& ddgi,
                              const ReconstructionSettings& s, const Context& ctx, ReconstructionError& out) {
  out = ReconstructionError{};
  ReconstructionReference reference;
  GIBAKE_TRY(trace_reconstruction_reference(prepared, lod, lights, sky, active_probes(ddgi), s, ctx, reference));
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] { finish_reconstruction(reference, ddgi, s, out); });
  return Status::ok();
}

namespace {

// The check's lighting from the bake's recorded settings, as `preview` reads them; its path
// length stays the reference's own.
Status check_lighting(const PreparedScene& prepared, const PreviewSettings& lighting,
                      std::vector<kernels::ShadeLight>& lights, Sky& sky) {
  sky.constant = float3{lighting.sky[0], lighting.sky[1], lighting.sky[2]};
  if (!lighting.sky_hdr.empty()) {
    GIBAKE_TRY(load_sky_exr(lighting.sky_hdr, sky));
    sky.scale = lighting.sky_hdr_scale;
  }
  lights = shade_lights(prepared.scene(), lighting.suns);
  return Status::ok();
}

}  // namespace

Status measure_bake_reconstruction(const PreparedScene& prepared, const TextureLod& lod, const loader::BakeFile& bake,
                                   const uint32_t* only_volume, ReconstructionSettings settings, const Context& ctx,
                                   ReconstructionError& out) {
  if (bake.ddgi_volumes().empty()) return Status::invalid("", "DDGI volume", "the bake file has no DDGI volume");
  if (only_volume && *only_volume >= bake.ddgi_volumes().size())
    return Status::invalid("", "DDGI volume", "the bake file has " + std::to_string(bake.ddgi_volumes().size()) +
                                                  " DDGI volume(s), asked for volume " + std::to_string(*only_volume));
  PreviewSettings lighting;
  apply_bake_lighting(bake, lighting, ctx);
  Sky sky;
  std::vector<kernels::ShadeLight> lights;
  GIBAKE_TRY(check_lighting(prepared, lighting, lights, sky));
  if (only_volume) return measure_reconstruction(prepared, lod, lights, sky, bake.ddgi_volumes()[*only_volume], settings, ctx, out);
  return measure_reconstruction(prepared, lod, lights, sky, bake, settings, ctx, out);
}

bool same_positions(const std::vector<float3>& a, const std::vector<float3>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z)) return false;
  return true;
}

std::vector<float3> active_probe_positions(const std::vector<const DdgiResult*>& volumes) {
  std::vector<float3> out;
  for (const DdgiResult* r : volumes) {
    const int32_t X = r->desc.counts[0], Y = r->desc.counts[1];
    const int32_t n = r->desc.probe_count();
    for (int32_t p = 0; p < n; ++p) {
      if (size_t(p) < r->states.size() && r->states[size_t(p)] == ProbeState::Inactive) continue;
      // loader::DdgiVolume::probe_position's arithmetic: grid_min + coord * spacing, then + offset.
      const int32_t c[3] = {p % X, (p / X) % Y, p / (X * Y)};
      float at[3];
      for (int a = 0; a < 3; ++a) {
        const float offset = r->offsets.size() >= size_t(p) * 3 + 3 ? r->offsets[size_t(p) * 3 + size_t(a)] : 0.f;
        at[a] = r->desc.grid_min[a] + float(c[a]) * r->desc.spacing[a];
        at[a] = at[a] + offset;
      }
      out.push_back(float3{at[0], at[1], at[2]});
    }
  }
  return out;
}

Status trace_bake_reconstruction_reference(const PreparedScene& prepared, const TextureLod& lod,
                                           const std::string& settings_json, const std::vector<float3>& probes,
                                           ReconstructionSettings settings, const Context& ctx,
                                           ReconstructionReference& out) {
  PreviewSettings lighting;
  apply_settings_lighting(settings_json, lighting, ctx);
  Sky sky;
  std::vector<kernels::ShadeLight> lights;
  GIBAKE_TRY(check_lighting(prepared, lighting, lights, sky));
  return trace_reconstruction_reference(prepared, lod, lights, sky, probes, settings, ctx, out);
}

VisibleSurface visible_surface(const PreparedScene& prepared, const TextureLod& lod, const float3& origin,
                               const float3& dir, float reach) {
  // The ray ends a little beyond the reach (a closer hit is the same hit whatever the ray's end);
  // the reach itself is measured from the point found, as a caller reads it.
  constexpr float kReachMargin = 1.001f;
  const SurfacePoint sp = surface_at(prepared, lod, origin, dir, 0.f, reach * kReachMargin);
  VisibleSurface out;
  if (!sp.valid || !(kernels::length(sp.p - origin) <= reach)) return out;
  out.valid = true;
  out.p = sp.p;
  out.n = sp.n;
  out.ng = sp.ng;
  return out;
}

Status trace_surface_irradiance(const PreparedScene& prepared, const TextureLod& lod, const std::string& settings_json,
                                const std::vector<VisibleSurface>& points, uint32_t rays, uint64_t seed,
                                ReferencePathDevice* device, const Context& ctx, std::vector<SurfaceLight>& out,
                                const ProbeField* probe_field, bool whole_paths_too, int roulette_depth,
                                EndedPathHits* keep) {
  if (rays < 1 || rays > (1u << 16))
    return Status::error(ExitCode::BadArguments, "", "--fit-paths", "must be between 1 and 65536");
  PreviewSettings lighting;
  apply_settings_lighting(settings_json, lighting, ctx);
  Sky sky;
  std::vector<kernels::ShadeLight> lights;
  GIBAKE_TRY(check_lighting(prepared, lighting, lights, sky));
  const EmitterTable emitters(prepared.scene());
  ReconstructionSettings s;
  s.seed = seed;
  s.roulette_depth = roulette_depth;
  PathSetup path = reference_path_setup(prepared, lod, lights, sky, emitters, s);
  path.probe_field = probe_field;
  // Paths that only end in the probes are the CPU's. With both estimates, a device that reads the
  // field's probes ends each whole path there too; otherwise the CPU traces the ended ones.
  if (probe_field && !whole_paths_too) device = nullptr;
  std::vector<PointSums> sums;
  std::vector<size_t> index;  // of each traced point in `points`
  for (size_t i = 0; i < points.size(); ++i) {
    const VisibleSurface& v = points[i];
    if (!v.valid) continue;
    SurfacePoint sp;
    sp.valid = true;
    sp.p = v.p;
    sp.n = v.n;
    sp.ng = v.ng;
    sums.push_back(PointSums{sp, offset_origin(path.trace, v.p, v.ng), kernels::rng_hash(seed, i, 0, kPathSalt), rays});
    index.push_back(i);
  }
  std::vector<PointSums*> all;
  for (PointSums& pt : sums) all.push_back(&pt);
  if (device && !device->lights_match(lights, sky)) device = nullptr;
  const bool keeping = keep && probe_field && whole_paths_too;
  std::vector<EndedPathHits::Point> kept_points(keeping ? points.size() : 0);
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  Status traced;
  ReferencePathDevice* ending = nullptr;  // the device that ends the paths too (device is null once it fails)
  arena->execute([&] {
    const bool device_ends = device && probe_field && whole_paths_too && !keeping && probe_field->file() &&
                             device->end_paths_in(probe_field->file()).is_ok();
    if (device_ends) ending = device;
    traced = paths_on_device(device, path, all, device_ends);
    const EndedPaths ended = !probe_field || !whole_paths_too     ? EndedPaths::None
                             : device && (device_ends || keeping) ? EndedPaths::None
                             : device                             ? EndedPaths::Only
                                                                  : EndedPaths::Also;
    // On the CPU a chunk of points at a time, so that the user sees it move (each point is its own
    // sum: the chunks change no bytes).
    constexpr size_t kProgressChunk = 8192;
    for (size_t first = 0; (!device || ended == EndedPaths::Only) && first < all.size(); first += kProgressChunk) {
      ctx.report("surface fit", double(first), double(all.size()));
      tbb::parallel_for(
          tbb::blocked_range<size_t>(first, std::min(all.size(), first + kProgressChunk), 1),
          [&](const tbb::blocked_range<size_t>& range) {
            for (size_t k = range.begin(); k < range.end(); ++k)
              trace_point(path, *all[k], ended, kept_points.empty() ? nullptr : &kept_points[index[k]]);
          },
          tbb::simple_partitioner());
    }
    ctx.report("surface fit", double(all.size()), double(all.size()));
    if (keep) keep->complete = keeping && ended == EndedPaths::Also;
  });
  if (ending) ending->end_paths_in(nullptr);  // the probes' device memory back
  if (keep) keep->points = std::move(kept_points);
  if (!traced)
    ctx.warning("surface fit: the paths failed on the device (" + traced.message() + "); traced on the CPU instead");
  out.assign(points.size(), SurfaceLight{});
  for (size_t k = 0; k < sums.size(); ++k) {
    const PointSums& pt = sums[k];
    SurfaceLight& o = out[index[k]];
    o.irradiance = pt.sum * (kernels::kPi / float(pt.rays));
    o.probe_lit = pt.ended_sum * (kernels::kPi / float(pt.rays));
    for (int h = 0; h < 2; ++h) {
      const double n = double(std::max(1u, pt.half_count[h]));  // the same paths' halves, wherever traced
      o.half[h] = float(kernels::kPi * pt.half_lum[h] / n);
      o.probe_half[h] = float(kernels::kPi * pt.ended_half_lum[h] / n);
    }
  }
  return Status::ok();
}

Status finish_bake_reconstruction(const PreparedScene& prepared, const TextureLod& lod, const loader::BakeFile& bake,
                                  const ReconstructionReference& reference, ReconstructionSettings settings,
                                  const Context& ctx, ReconstructionError& out) {
  if (bake.ddgi_volumes().empty()) return Status::invalid("", "DDGI volume", "the bake file has no DDGI volume");
  if (!same_positions(reference.probes, active_probes(bake)))  // never expected: measured from the file instead
    return measure_bake_reconstruction(prepared, lod, bake, nullptr, settings, ctx, out);
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] { finish_reconstruction(reference, bake, settings, out); });
  return Status::ok();
}

std::string reconstruction_summary(const ReconstructionError& e) {
  char line[512];
  // No counted patch: nothing was measured, and ratios of nothing must not read as figures.
  if (e.counted == 0) {
    std::snprintf(line, sizeof line,
                  "reconstruction error (%s, %u patches of 4x4 points): skipped: %s, so nothing was measured; %.2f s",
                  e.source.c_str(), e.patches,
                  e.patches == 0 ? "no patch met a visible surface"
                                 : "no patch's path-traced reference is lit (the scene brings no light to them)",
                  e.seconds);
    return line;
  }
  char again[128] = "";
  if (e.retraced > 0)
    std::snprintf(again, sizeof again, " (%u noisy patches traced again, up to %u paths a point)", e.retraced,
                  e.retraced_rays);
  std::snprintf(line, sizeof line,
                "reconstruction error (%s, %u patches of 4x4 points): %.0f%% within 10%% of the path-traced truth, "
                "baked/reference "
                "p10 %.2f, median %.2f, p90 %.2f; indirect light alone %.0f%% within 10%%, median %.2f; reference "
                "noise %.1f%%%s; %.2f s",
                e.source.c_str(), e.counted, 100.0 * e.shaded.within, e.shaded.p10, e.shaded.median, e.shaded.p90,
                100.0 * e.indirect.within, e.indirect.median, 100.0 * e.reference_noise, again, e.seconds);
  return line;
}

}  // namespace gibake
