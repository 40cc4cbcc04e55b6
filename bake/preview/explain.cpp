// One pixel of a lit preview, explained (see explain.h).
#include "bake/preview/explain.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "bake/run/arena.h"
#include "bake/scene/emitters.h"
#include "bake/scene/material.h"
#include "bake/scene/texture_lod.h"
#include "bake/trace/path_gather.h"
#include "bake/trace/probe_rays.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"

namespace gibake {
using kernels::float3;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kAlongNormal[3] = {0.1f, 0.25f, 0.5f};  // of the finest listed spacing
constexpr uint64_t kExplainTag = 0x6578706c61696e31ull;

using kernels::luminance;
float luminance(const loader::Rgb& c) { return luminance(c.data()); }

Status bad(const std::string& what) { return Status::error(ExitCode::BadArguments, "", "--explain", what); }

// Irradiance for normal n at `origin`: pi x the mean radiance of cosine-distributed paths, each
// paired with an emitter sample as the reference's are (trace_surface_radiance). The paired samples
// are spread as a lattice, so the error read from their spread is an upper estimate.
TracedIrradiance traced_irradiance(const PathSetup& path, const float3& origin, const float3& n, uint32_t paths,
                                   uint64_t seed, uint64_t estimate) {
  const uint64_t light_shift = kernels::rng_hash(seed, estimate, kernels::kProbeLightShiftRay, kExplainTag);
  TraceCounters tc;
  double sum = 0.0, sum2 = 0.0;
  for (uint32_t k = 0; k < paths; ++k) {
    const uint64_t key = kernels::rng_hash(seed, estimate, uint64_t(k), kExplainTag);
    const float3 d = kernels::sample_cosine_hemisphere(n, kernels::rng_uniform(key, 0), kernels::rng_uniform(key, 1));
    float u[3];
    kernels::probe_light_uniforms(light_shift, k, paths, u);
    const double l = luminance(trace_surface_radiance(path, origin, n, n, d, true, u, key, tc));
    sum += l;
    sum2 += l * l;
  }
  TracedIrradiance out;
  const double mean = sum / paths;
  out.lux = kernels::kPi * mean;
  const double var = paths > 1 ? std::max(0.0, (sum2 - sum * mean) / (paths - 1)) : 0.0;
  out.relative_error = mean > 0.0 ? std::sqrt(var / paths) / mean : 0.0;
  return out;
}

// The volumes the sampler reads at p, with their shares.
std::vector<loader::VolumeShare> volume_shares(const loader::BakeFile& bake, const PreviewSettings& s,
                                               const loader::Vec3& p, const loader::Vec3& n) {
  if (s.volume >= 0) return {{uint32_t(s.volume), 1.f}};
  return bake.ddgi_shares(p, n, s.sample);
}

// The probes each listed volume weighs at p, with their share of the answer and baked irradiance.
void list_probes(const loader::BakeFile& bake, const PreviewSettings& s, const loader::Vec3& p, const loader::Vec3& n,
                 ExplainedPixel& out) {
  out.spacing = 0.f;
  for (const loader::VolumeShare& vs : volume_shares(bake, s, p, n)) {
    const loader::DdgiVolume& vol = bake.ddgi_volumes()[vs.volume];
    const float finest = vol.finest_spacing();
    if (std::isfinite(finest) && (out.spacing == 0.f || finest < out.spacing)) out.spacing = finest;
    loader::Rgb unused;
    float sight = 0.f;
    vol.try_sample_irradiance(p, n, unused, sight, s.sample);
    out.sights.emplace_back(vs.volume, sight);
    loader::ProbeWeight weights[8];
    const uint32_t count = vol.probe_weights(p, n, weights, s.sample);
    float total = 0.f;
    for (uint32_t i = 0; i < count; ++i) total += weights[i].weight;
    for (uint32_t i = 0; i < count; ++i) {
      ExplainedProbe e;
      e.volume = vs.volume;
      e.weight = weights[i];
      e.share = vs.share * weights[i].weight / total;
      const loader::Vec3 at = vol.probe_position(weights[i].probe);
      e.position = float3{at[0], at[1], at[2]};
      e.state = vol.state(weights[i].probe);
      e.behind = (at[0] - p[0]) * n[0] + (at[1] - p[1]) * n[1] + (at[2] - p[2]) * n[2] < 0.f;
      const bool atlas = s.sample.use_irradiance_atlas && vol.has_irradiance();
      e.baked_lux =
          luminance(atlas ? vol.atlas_irradiance(weights[i].probe, n) : vol.sh_irradiance(weights[i].probe, n));
      out.probes.push_back(e);
    }
  }
}

// Every path-traced irradiance of the explanation, in parallel (each keyed by its own index).
void trace_estimates(const PathSetup& path, const float3& surface_origin, const Context& ctx, uint64_t seed,
                     ExplainedPixel& out) {
  std::vector<float3> origins{surface_origin};
  for (float f : kAlongNormal) origins.push_back(out.point + out.normal * (f * out.spacing));
  for (const ExplainedProbe& p : out.probes) origins.push_back(p.position);
  std::vector<TracedIrradiance> traced(origins.size());
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] {
    tbb::parallel_for(size_t(0), origins.size(), [&](size_t i) {
      traced[i] = traced_irradiance(path, origins[i], out.normal, out.paths, seed, uint64_t(i));
    });
  });
  out.here = traced[0];
  if (out.spacing > 0.f)
    for (size_t i = 0; i < 3; ++i) out.along_normal.emplace_back(kAlongNormal[i] * out.spacing, traced[1 + i]);
  out.exact_probes_lux = 0.0;
  for (size_t i = 0; i < out.probes.size(); ++i) {
    out.probes[i].traced = traced[4 + i];
    out.exact_probes_lux += double(out.probes[i].share) * traced[4 + i].lux;
  }
}

Status check_explain(const loader::BakeFile& bake, const PreviewSettings& s, const ExplainSettings& e) {
  if (bake.ddgi_volumes().empty()) return bad("explains how DDGI probes light a pixel; the bake holds none");
  if (s.volume >= 0 && size_t(s.volume) >= bake.ddgi_volumes().size())
    return Status::invalid("", "--volume",
                           "the bake file has " + std::to_string(bake.ddgi_volumes().size()) +
                               " DDGI volume(s), asked for volume " + std::to_string(s.volume));
  if (e.x < 0 || e.y < 0 || e.x >= s.width || e.y >= s.height)
    return bad("pixel " + std::to_string(e.x) + "," + std::to_string(e.y) + " lies outside the " +
               std::to_string(s.width) + "x" + std::to_string(s.height) + " image");
  if (e.paths < 16 || e.paths > (1u << 24)) return bad("paths per estimate must be between 16 and 16777216");
  return Status::ok();
}

}  // namespace

Status explain_pixel(const PreparedScene& prepared, const loader::BakeFile& bake, const PreviewSettings& in,
                     const ExplainSettings& explain, const Context& ctx, ExplainedPixel& out) {
  const Scene& scene = prepared.scene();
  PreviewSettings s = in;
  if (s.lights_from_bake) apply_bake_lighting(bake, s, ctx);
  GIBAKE_TRY(check_explain(bake, s, explain));
  out = ExplainedPixel();
  out.width = s.width;
  out.height = s.height;
  out.paths = explain.paths;
  PreviewCamera cam;
  GIBAKE_TRY(resolve_camera(scene, s, cam, out.camera));
  Sky sky;
  std::vector<kernels::ShadeLight> lights;
  GIBAKE_TRY(make_preview_lights(scene, s, sky, lights));
  const TextureLod lod(scene, ctx);
  const EmitterTable emitters(scene);
  TraceSetup view;  // the lit view's: textures at the pixel's footprint
  view.prepared = &prepared;
  view.sky = &sky;
  view.lights = lights.data();
  view.light_count = int(lights.size());
  view.seed = s.seed;
  view.lod = &lod;
  view.cone_spread = 2.f * cam.tan_half / float(s.height);

  const float3 dir = cam.ray(float(explain.x) + 0.5f, float(explain.y) + 0.5f, s.width, s.height);
  const TraceHit hit = prepared.intersect(cam.eye, dir, 0.f, kInf);
  if (hit.t < 0.f) return Status::ok();
  out.hit = true;
  out.triangle = hit.triangle;
  const Material& mat = hit_material(scene, hit);
  out.material = mat.name;
  const float3 ng = hit.front ? hit.ng : -hit.ng;
  out.point = cam.eye + dir * hit.t;
  const SurfaceSample surf =
      hit_surface(scene, hit, TextureFootprint{&lod, view.cone_spread * hit.t, kernels::dot(dir, ng)});
  float3 n = kernels::dot(surf.normal, surf.normal) == 0.f ? ng : surf.normal;
  if (kernels::dot(n, ng) < 0.f) n = -n;
  out.normal = n;
  out.albedo = surf.albedo;
  out.back_face = !hit.front && !mat.double_sided;
  if (out.back_face) return Status::ok();  // black in the lit view, as in the bake: nothing to weigh
  TraceCounters tc;
  const float3 origin = offset_origin(view, out.point, ng);
  out.direct = shade_punctual(view, origin, n, ng, surf.albedo, surf.emission, 0.f, tc, nullptr);
  const loader::Vec3 p{out.point.x, out.point.y, out.point.z}, nv{n.x, n.y, n.z};
  const DdgiReader reader = s.volume >= 0 ? DdgiReader(bake.ddgi_volumes()[size_t(s.volume)]) : DdgiReader(bake);
  const loader::Rgb e = reader.sample(p, nv, s.sample);
  out.baked = float3{e[0], e[1], e[2]};
  out.baked_lux = luminance(e);
  list_probes(bake, s, p, nv, out);

  // The truth is traced as the reference traces it: full-resolution textures, converged paths.
  PathSetup path;
  path.trace = view;
  path.trace.cone_spread = 0.f;
  path.emitters = &emitters;
  path.bounces = s.bounces;
  path.roulette_depth = s.roulette_depth;
  trace_estimates(path, origin, ctx, s.seed, out);
  return Status::ok();
}

namespace {

std::string fmt(const char* f, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, a);
  return buf;
}

std::string vec(const float3& v, const char* f = "%.3g") {
  return "(" + fmt(f, v.x) + ", " + fmt(f, v.y) + ", " + fmt(f, v.z) + ")";
}

std::string traced_text(const TracedIrradiance& t) {
  return fmt("%.4g lux", t.lux) + fmt(" +- %.1f%%", 100.0 * t.relative_error);
}

const char* state_name(uint32_t state) {
  return state == GIBAKE_PROBE_SKY_ONLY ? "sky-only" : state == GIBAKE_PROBE_INACTIVE ? "inactive" : "active";
}

std::string ratio(double a, double b) { return b > 0.0 ? fmt("%.3f", a / b) : std::string("-"); }

}  // namespace

BehindSurface probes_behind(const ExplainedPixel& e) {
  BehindSurface out;
  double all = 0.0;
  for (const ExplainedProbe& p : e.probes) {
    all += double(p.share) * p.baked_lux;
    if (!p.behind || !(p.share > 0.f)) continue;
    ++out.probes;
    out.weight += p.share;
    out.light += double(p.share) * p.baked_lux;
  }
  out.light = all > 0.0 ? out.light / all : 0.0;
  return out;
}

std::string explain_text(const ExplainedPixel& e) {
  std::string t;
  if (!e.hit) return "the pixel sees no surface (the sky): nothing the probes light\n";
  if (e.back_face)
    return "the pixel sees the back of a single-sided surface (triangle " + std::to_string(e.triangle) +
           "): black in the lit view, as the bake treats it\n";
  t += "surface: triangle " + std::to_string(e.triangle) +
       (e.material.empty() ? "" : ", material '" + e.material + "'") + ", point " + vec(e.point, "%.3f") +
       " m, normal " + vec(e.normal, "%.3f") + ", albedo " + vec(e.albedo) + "\n";
  t += "lit: " + fmt("%.4g", luminance(e.direct + e.albedo * e.baked * (1.f / kernels::kPi))) +
       " cd/m^2 = direct light and emission " + fmt("%.4g", luminance(e.direct)) +
       " + albedo x baked irradiance / pi " + fmt("%.4g", luminance(e.albedo * e.baked * (1.f / kernels::kPi))) + "\n";
  t += "irradiance (indirect, luminance; path-traced with " + std::to_string(e.paths) + " paths each):\n";
  auto row = [&](const std::string& label, const std::string& value) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-28s %s\n", label.c_str(), value.c_str());
    t += line;
  };
  row("baked (the sampler)", fmt("%.4g lux", e.baked_lux));
  row("path-traced here", traced_text(e.here) + "   baked / path-traced " + ratio(e.baked_lux, e.here.lux));
  for (const auto& [metres, traced] : e.along_normal)
    row("path-traced " + fmt("%.3g m", metres) + " above it", traced_text(traced));
  row("exact probes",
      fmt("%.4g lux", e.exact_probes_lux) + " (each probe's path-traced value, weighed as the sampler weighs it)");
  t += "the error in two: the probes' own (baked / exact probes) " + ratio(e.baked_lux, e.exact_probes_lux) +
       ", the interpolation's (exact probes / path-traced here) " + ratio(e.exact_probes_lux, e.here.lux) + "\n";
  t += "probes (" + std::to_string(e.probes.size()) + "; spacing " + fmt("%.3g m", e.spacing) + "):\n";
  t += "  volume  probe     position (m)              state     distance  backface  visibility  trilinear  share   "
       "baked lux  path-traced lux\n";
  for (const ExplainedProbe& p : e.probes) {
    char line[256];
    std::snprintf(line, sizeof line, "  %-6u  %-8u  %-24s  %-8s  %8.3f  %8.3f  %10.3f  %9.3f  %5.1f%%  %9.4g  %s%s\n",
                  p.volume, p.weight.probe, vec(p.position, "%.2f").c_str(), state_name(p.state),
                  double(p.weight.distance), double(p.weight.backface), double(p.weight.visibility),
                  double(p.weight.trilinear), 100.0 * p.share, p.baked_lux, traced_text(p.traced).c_str(),
                  p.behind ? "  behind" : "");
    t += line;
  }
  const BehindSurface behind = probes_behind(e);
  if (behind.probes > 0)
    t += "behind the surface: " + std::to_string(behind.probes) + (behind.probes == 1 ? " probe" : " probes") +
         " past its tangent plane carry " + fmt("%.1f%%", 100.0 * behind.weight) + " of the weight and " +
         fmt("%.0f%%", 100.0 * behind.light) +
         " of the baked irradiance: light from the surface's far side, let in by the normal bias within the "
         "sampler's fade (finer probes there shrink it)\n";
  for (const auto& [volume, sight] : e.sights) {
    t += "volume " + std::to_string(volume) + ": sight " + fmt("%.3g", sight);
    if (sight < GIBAKE_DDGI_FULL_SIGHT)
      t += " (under " + fmt("%.3g", GIBAKE_DDGI_FULL_SIGHT) + ": its probes barely see the point; its blend weight x " +
           fmt("%.3g", sight / GIBAKE_DDGI_FULL_SIGHT) + ", the next volume answers the rest)";
    t += "\n";
  }
  return t;
}

}  // namespace gibake
