#include "bake/trace/path_gather.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bake/scene/material.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"

namespace gibake {
using kernels::float3;
using kernels::HitRecord;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Density of a probe ray's direction: uniform over the sphere (a randomly rotated Fibonacci set,
// kernels/ray_gen.h, puts each ray anywhere with equal probability).
constexpr float kProbeRayPdf = 1.f / (4.f * kernels::kPi);

// Random stream of a vertex: 8 numbers per vertex, above the streams trace_probe_rays uses.
enum Stream : uint32_t { kLightChoice = 0, kEmitterPick = 1, kEmitterU = 2, kEmitterV = 3, kBounceU = 4,
                         kBounceV = 5, kRoulette = 6 };
uint32_t stream(int depth, Stream s) { return 16u + 8u * static_cast<uint32_t>(depth) + s; }
// A path's k-th pass-through choice at glass: far above any vertex's streams. Counted per choice,
// not per crossing: a path that chose to scatter at one pane must draw afresh at the next.
uint32_t glass_stream(int k) { return 1u << 20 | static_cast<uint32_t>(k); }

struct GlassCount {
  int crossings = 0;  // surfaces crossed (at most kMaxGlassCrossings a path)
  int draws = 0;      // random numbers drawn for the choice
};

bool is_black(const float3& v) { return v.x <= 0.f && v.y <= 0.f && v.z <= 0.f; }

void record(std::vector<CapturedRay>* capture, const float3& o, const float3& d, float tfar, uint32_t kind) {
  if (capture) capture->push_back(CapturedRay{{o.x, o.y, o.z}, {d.x, d.y, d.z}, 0.f, tfar, kind});
}

// One surface point of a path, on the side the path arrived from.
struct Vertex {
  float3 p, ng, n;  // position, geometric and shading normal facing the incoming ray
  SurfaceSample surf;
};

// A point on an emissive triangle picked by power (uniforms u0, u1, u2), as seen from `from`: the
// unit direction to it, its distance, the solid-angle density of having picked it and its emission
// towards `from`. False when it gives nothing: the back of a single-sided emitter, masked out, black.
struct EmitterPoint {
  float3 w, le;
  float dist = 0.f, pdf = 0.f;
};
bool pick_emitter_point(const PathSetup& ps, const float3& from, float u0, float u1, float u2, EmitterPoint& out) {
  const Scene& scene = ps.trace.prepared->scene();
  const EmitterSample es = ps.emitters->sample(u0, u1, u2);
  const float3 to = es.position - from;
  out.dist = kernels::length(to);
  if (!(out.dist > 0.f)) return false;
  out.w = to * (1.f / out.dist);
  const Material& m = triangle_material(scene, es.triangle);
  float cos_l = -kernels::dot(es.normal, out.w);
  if (m.double_sided) cos_l = std::fabs(cos_l);
  if (cos_l <= 0.f) return false;  // the back of a single-sided emitter
  const float cutoff = alpha_cutoff_of(m, ps.trace.prepared->blend_cutoff());
  if (cutoff >= 0.f && surface_alpha(scene, es.triangle, es.u, es.v) < cutoff) return false;  // masked out
  out.le = surface_sample(scene, es.triangle, es.u, es.v).emission;
  if (is_black(out.le)) return false;
  out.pdf = kernels::area_to_solid_angle_pdf(es.pdf_area, out.dist, cos_l);
  return out.pdf > 0.f;
}

// The share of the probe's light samples that go to the sky map (the rest to the emitters): half
// each when the scene has both.
float probe_sky_share(const PathSetup& ps) {
  const bool emitters = ps.emitters && !ps.emitters->empty(), sky = ps.trace.sky && ps.trace.sky->sampled();
  return sky ? (emitters ? 0.5f : 1.f) : 0.f;
}

// A light sample seen from `origin`, from the uniforms `u`: with u[0] below `sky_share` a direction
// from the sky map, else a point on an emissive triangle picked by power (u[0] rescaled). Its
// direction, radiance, distance (infinite for the sky) and solid-angle density including its
// technique's share; false when it gives nothing (no shadow ray is then cast).
struct LightPoint {
  float3 w, le;
  float tfar = kInf, pdf = 0.f;
};
bool pick_light(const PathSetup& ps, const float3& origin, const float u[3], float sky_share, LightPoint& out) {
  if (u[0] < sky_share) {
    out.w = ps.trace.sky->sample(u[1], u[2], out.pdf);
    out.pdf *= sky_share;
    if (!(out.pdf > 0.f)) return false;
    out.le = ps.trace.sky->radiance(out.w);
    return !is_black(out.le);
  }
  EmitterPoint e;
  if (!pick_emitter_point(ps, origin, (u[0] - sky_share) / (1.f - sky_share), u[1], u[2], e)) return false;
  out.w = e.w;
  out.le = e.le;
  out.pdf = (1.f - sky_share) * e.pdf;
  out.tfar = e.dist * (1.f - 1e-3f);
  return true;
}

// The light let through a shadow ray from `origin` to the light sample (1 or 0 without glass).
float3 light_visibility(const PathSetup& ps, const float3& origin, const LightPoint& l, TraceCounters& counters,
                        std::vector<CapturedRay>* capture) {
  ++counters.shadow_rays;
  record(capture, origin, l.w, l.tfar, CapturedRay::kShadow);
  return transmittance(ps.trace, origin, l.w, l.tfar);
}

// The probe's own light sample paired with one of its rays, from the uniforms `u`
// (kernels::probe_light_uniforms, stratified over the probe's samples of a batch; pick_light),
// seen from the probe through a shadow ray and weighted against the probe's uniform rays (density
// 1/(4 pi), one ray per sample: the power heuristic without counts). Its radiance is stored
// divided by 4 pi so the integrator's uniform-sphere norm 4 pi / N turns it into
// (1/N) sum L w / pdf (kernels/integrate.h).
kernels::RaySample sample_probe_light(const PathSetup& ps, const float3& origin, const float u[3], float sky_share,
                                      TraceCounters& counters, std::vector<CapturedRay>* capture) {
  kernels::RaySample s{{0.f, 0.f, 1.f, 0.f}, {0.f, 0.f, 0.f, 0.f}};
  LightPoint lp;
  if (!pick_light(ps, origin, u, sky_share, lp)) return s;
  kernels::store3(s.dir_depth, lp.w);
  const float3 through = light_visibility(ps, origin, lp, counters, capture);
  if (is_black(through)) return s;
  const float weight = kernels::power_heuristic(lp.pdf, kProbeRayPdf);
  const float3 l = lp.le * (weight / (4.f * kernels::kPi * lp.pdf));
  kernels::store3(s.radiance, ps.trace.prepared->has_transmission() ? l * through : l);
  return s;
}

// Light from one emitter sample (pick_light from the uniforms `u`, no share for the sky map)
// reflected at a point of shading normal n, geometric normal ng and albedo `albedo` towards any
// direction: albedo L cos w / (pi pdf), w the power heuristic against the cosine-weighted bounce ray
// that could find the same emitter. With albedo 1 it is the emitter sample's share of the
// irradiance estimate pi / N sum (paired with N cosine-weighted rays).
float3 sample_emitter_at(const PathSetup& ps, const float3& n, const float3& ng, const float3& albedo,
                         const float3& origin, const float u[3], TraceCounters& counters,
                         std::vector<CapturedRay>* capture) {
  LightPoint lp;
  if (!pick_light(ps, origin, u, /*sky_share=*/0.f, lp)) return {};
  const float cos_x = kernels::dot(n, lp.w);
  if (cos_x <= 0.f || kernels::dot(ng, lp.w) <= 0.f) return {};
  const float3 through = light_visibility(ps, origin, lp, counters, capture);
  if (is_black(through)) return {};
  const float weight = kernels::power_heuristic(lp.pdf, cos_x / kernels::kPi);
  const float3 l = albedo * lp.le * (cos_x * weight / (kernels::kPi * lp.pdf));
  return ps.trace.prepared->has_transmission() ? l * through : l;
}

// Reflected radiance at v from one emissive triangle chosen by power, weighted against the bounce
// ray that could find the same emitter (every vertex casts one, the last one for emission only).
float3 sample_emitter(const PathSetup& ps, const Vertex& v, const float3& shadow_org, uint64_t key, int depth,
                      TraceCounters& counters, std::vector<CapturedRay>* capture) {
  const float u[3] = {kernels::rng_uniform(key, stream(depth, kEmitterPick)),
                      kernels::rng_uniform(key, stream(depth, kEmitterU)),
                      kernels::rng_uniform(key, stream(depth, kEmitterV))};
  return sample_emitter_at(ps, v.n, v.ng, v.surf.albedo, shadow_org, u, counters, capture);
}

// The ray that found a hit, as MIS sees it: its solid-angle density (0: nothing else samples what
// it finds, weight 1) and the shares of the light technique that could have sampled the same
// direction: emitters (a vertex's emitter sample: 1) and the sky map (the probe's pair only).
struct RayMis {
  float pdf = 0.f;
  float emitter_share = 1.f, sky_share = 0.f;
};

// MIS weight of emission that `ray` found `dist` from its vertex. `ng` faces the ray.
float emission_weight(const PathSetup& ps, const TraceHit& hit, const float3& dir, const float3& ng, const RayMis& ray,
                      float dist) {
  const float pdf_area = ps.emitters ? ps.emitters->pdf_area(hit.triangle) : 0.f;
  if (!(ray.pdf > 0.f && pdf_area > 0.f && ray.emitter_share > 0.f)) return 1.f;
  return kernels::power_heuristic(
      ray.pdf, ray.emitter_share * kernels::area_to_solid_angle_pdf(pdf_area, dist, -kernels::dot(dir, ng)));
}

// MIS weight of the sky that `ray` found along dir (1 unless the probe's pair samples the map).
float sky_weight(const TraceSetup& ts, const float3& dir, const RayMis& ray) {
  if (!(ray.pdf > 0.f && ray.sky_share > 0.f)) return 1.f;
  return kernels::power_heuristic(ray.pdf, ray.sky_share * ts.sky->pdf(dir));
}

// Thin glass (Material::transmission t > 0) at `hit`: with probability t the path passes straight
// on, its throughput times the base colour (t x colour / t), to the next hit; otherwise (1 - t)
// the surface scatters as an opaque one, its albedo times (1 - t) / (1 - t). The choice, not a
// split, keeps one path per ray; t = 1 (most glass) needs no random number. A crossing is not a
// vertex: it uses no bounce, and `seg` (the distance since the last vertex, for the emitters'
// MIS density) grows by the segment. Emission of a crossed surface (its front, or either side when
// double-sided) counts as at a vertex. False when the path ends (sky or nothing behind the glass).
bool cross_glass(const PathSetup& ps, float3& org, const float3& dir, TraceHit& hit, uint64_t key, const RayMis& ray,
                 GlassCount& glass, float3& throughput, float3& radiance, float& seg, float& cone_width,
                 TraceCounters& counters, std::vector<CapturedRay>* capture) {
  const TraceSetup& ts = ps.trace;
  const Scene& scene = ts.prepared->scene();
  for (;;) {
    const Material& m = hit_material(scene, hit);
    if (!(m.transmission > 0.f) || glass.crossings >= kMaxGlassCrossings) return true;
    const float3 ng_far = hit.front ? -hit.ng : hit.ng;  // the side the ray leaves by
    const float width = cone_width + ts.cone_spread * hit.t;
    const SurfaceSample s = hit_surface(scene, hit, TextureFootprint{ts.lod, width, kernels::dot(dir, ng_far)});
    if (s.transmission < 1.f && kernels::rng_uniform(key, glass_stream(glass.draws++)) >= s.transmission) return true;
    ++glass.crossings;
    const float3 p = org + dir * hit.t;
    cone_width = width;
    if (!is_black(s.emission) && (hit.front || m.double_sided))
      radiance += throughput * s.emission * emission_weight(ps, hit, dir, -ng_far, ray, seg + hit.t);
    throughput = throughput * s.albedo;
    if (is_black(throughput)) return false;
    seg += hit.t;
    org = offset_origin(ts, p, ng_far);
    hit = ts.prepared->intersect(org, dir, 0.f, kInf);
    ++counters.bounce_rays;
    record(capture, org, dir, kInf, CapturedRay::kProbe);
    if (hit.t < 0.f) {
      if (ts.sky) radiance += throughput * ts.sky->radiance(dir) * sky_weight(ts, dir, ray);
      return false;
    }
  }
}

// Radiance leaving the surface at `hit` towards org (the path from there on).
// `first`: the ray that found `hit` as MIS sees it (a probe ray paired with a light sample: its
// density and the pair's shares; else pdf 0, full weight).
// `probe_lit` (with ps.probe_field): the path goes on to its end, and the light it would have had
// ended at its first hit is written there (the whole path's when it does not end there).
float3 path_radiance(const PathSetup& ps, float3 org, float3 dir, TraceHit hit, uint64_t key, const RayMis& first,
                     TraceCounters& counters, std::vector<CapturedRay>* capture, EndedLight* probe_lit = nullptr) {
  const TraceSetup& ts = ps.trace;
  const Scene& scene = ts.prepared->scene();
  const bool have_emitters = ps.emitters && !ps.emitters->empty();
  // The bounce ray of the last vertex only looks for emission and sky (its direct light found by
  // the other technique); without either it cannot add anything.
  const bool last_ray_useful = have_emitters || (ts.sky && !ts.sky->is_black());
  float3 radiance{}, throughput{1.f, 1.f, 1.f};
  RayMis ray = first;  // the ray that found `hit`
  PunctualRays lit;    // a vertex's shadow rays (one set, reused: it is large)
  float cone_width = 0.f;  // ray-cone footprint (m): every segment widens it by spread x length
  const bool has_glass = ts.prepared->has_transmission();
  GlassCount glass;
  bool probe_lit_set = false;
  for (int depth = 0;; ++depth) {
    if (ts.lod && ts.cone_spread > 0.f) ts.lod->prefetch(hit.triangle);  // its footprint's mip level
    float seg = 0.f;  // distance from the last vertex to the glass the path passed through
    if (has_glass &&
        !cross_glass(ps, org, dir, hit, key, ray, glass, throughput, radiance, seg, cone_width, counters, capture))
      break;
    const Material& mat = hit_material(scene, hit);
    if (!hit.front && !mat.double_sided) break;  // inside a single-sided surface: black
    Vertex v;
    v.ng = hit.front ? hit.ng : -hit.ng;
    v.p = org + dir * hit.t;
    cone_width += ts.cone_spread * hit.t;
    // The base colour's texels load while the vertex's shadow rays are traced (PendingSurface).
    const PendingSurface pending =
        begin_hit_surface(scene, hit, TextureFootprint{ts.lod, cone_width, kernels::dot(dir, v.ng)});
    const SurfaceSample& geometry = pending.sample;  // all but the albedo
    v.n = kernels::dot(geometry.normal, geometry.normal) == 0.f ? v.ng : geometry.normal;
    if (kernels::dot(v.n, v.ng) < 0.f) v.n = -v.n;
    if (!is_black(geometry.emission))
      radiance += throughput * geometry.emission * emission_weight(ps, hit, dir, v.ng, ray, seg + hit.t);
    // Vertex bounces+1 was reached only to collect the emission the last bounce found.
    if (depth > ps.bounces) break;
    const float3 shadow_org = offset_origin(ts, v.p, v.ng);
    const float u_light = ts.random_light ? kernels::rng_uniform(key, stream(depth, kLightChoice)) : 0.f;
    cast_punctual(ts, shadow_org, v.n, v.ng, u_light, lit);
    v.surf = finish_surface_sample(pending);
    if (is_black(v.surf.albedo)) break;
    radiance += throughput * shade_cast(ts, lit, shadow_org, v.n, v.surf.albedo, float3{}, counters, capture);
    // The rest of the path is in the probes' light (emitters included), except at an emitter's own
    // surface: probes beside it see it at close range, so the path goes on there as a full one.
    if (ps.probe_field && depth == 0 && is_black(v.surf.emission)) {
      EndedLight here;
      here.base = radiance;
      here.weight = throughput * v.surf.albedo;
      here.p = v.p;
      here.n = v.n;
      here.at_hit = true;
      if (!probe_lit) {
        radiance = here.resolve(ps.probe_field);
        break;
      }
      *probe_lit = here;  // its field read later (EndedLight)
      probe_lit_set = true;
    }
    if (have_emitters) radiance += throughput * sample_emitter(ps, v, shadow_org, key, depth, counters, capture);
    if (depth == ps.bounces && !last_ray_useful) break;
    const float3 w = kernels::sample_cosine_hemisphere(v.n, kernels::rng_uniform(key, stream(depth, kBounceU)),
                                                       kernels::rng_uniform(key, stream(depth, kBounceV)));
    const float cos_n = kernels::dot(w, v.n);
    if (kernels::dot(w, v.ng) <= 0.f || cos_n <= 0.f) break;  // below the surface: no contribution
    throughput = throughput * v.surf.albedo;                  // f cos / pdf = (albedo/pi) cos / (cos/pi)
    const float survive = kernels::roulette_survival(throughput, depth + 1, ps.roulette_depth);
    if (survive < 1.f) {
      if (kernels::rng_uniform(key, stream(depth, kRoulette)) >= survive) break;
      throughput = throughput * (1.f / survive);
    }
    ray = RayMis{cos_n / kernels::kPi, 1.f, 0.f};  // a bounce: the vertex's emitter sample, no sky sample
    org = shadow_org;
    dir = w;
    hit = ts.prepared->intersect(org, dir, 0.f, kInf);
    ++counters.bounce_rays;
    record(capture, org, dir, kInf, CapturedRay::kProbe);
    if (hit.t < 0.f) {
      if (ts.sky) radiance += throughput * ts.sky->radiance(dir);
      break;
    }
  }
  if (probe_lit && !probe_lit_set) probe_lit->base = radiance;
  return radiance;
}

// Radiance arriving at `origin` along -dir: the sky where the ray meets nothing, else the path from
// its first hit, whose emission `first` weighs (RayMis{}: full weight).
float3 radiance_along(const PathSetup& ps, const float3& origin, const float3& dir, uint64_t key, const RayMis& first,
                      TraceCounters& counters, EndedLight* probe_lit = nullptr) {
  const TraceHit hit = ps.trace.prepared->intersect(origin, dir, 0.f, kInf);
  ++counters.rays;
  if (hit.t < 0.f) {
    const float3 sky = ps.trace.sky ? ps.trace.sky->radiance(dir) : float3{};  // rays alone sample the sky here
    if (probe_lit) probe_lit->base = sky;
    return sky;
  }
  return path_radiance(ps, origin, dir, hit, key, first, counters, nullptr, probe_lit);
}

}  // namespace

void trace_probe_paths(const PathSetup& ps, const float3& origin, uint32_t probe, uint32_t pass, const float* dirs,
                       uint32_t count, HitRecord* out, TraceCounters& counters, std::vector<CapturedRay>* capture,
                       kernels::RaySample* lights) {
  const TraceSetup& ts = ps.trace;
  const Scene& scene = ts.prepared->scene();
  const float sky_share = probe_sky_share(ps);
  const bool probe_lights = lights && ((ps.emitters && !ps.emitters->empty()) || sky_share > 0.f);
  const RayMis first = probe_lights ? RayMis{kProbeRayPdf, 1.f - sky_share, sky_share} : RayMis{};
  const uint64_t shift_key = kernels::rng_hash(ts.seed, probe, pass, kernels::kProbeLightShiftRay);
  for (uint32_t r = 0; r < count; ++r) {
    const float3 dir = kernels::load3(dirs + 3 * r);
    HitRecord rec;
    kernels::store3(rec.dir_t, dir);
    const TraceHit hit = ts.prepared->intersect(origin, dir, 0.f, kInf);
    record(capture, origin, dir, kInf, CapturedRay::kProbe);
    ++counters.rays;
    const uint64_t key = kernels::rng_hash(ts.seed, probe, pass, r);
    if (lights) {
      float u[3];
      kernels::probe_light_uniforms(shift_key, r, count, u);
      lights[r] = probe_lights ? sample_probe_light(ps, origin, u, sky_share, counters, capture) : kernels::RaySample{};
    }
    if (hit.t < 0.f) {
      rec.dir_t[3] = -1.f;
      rec.normal_kind[3] = kernels::kHitMiss;
      if (ts.sky) kernels::store3(rec.radiance0, ts.sky->radiance(dir) * sky_weight(ts, dir, first));
      out[r] = rec;
      continue;
    }
    rec.dir_t[3] = hit.t;
    const float3 ng = hit.front ? hit.ng : -hit.ng;
    if (!hit.front && !hit_material(scene, hit).double_sided) {
      rec.normal_kind[3] = kernels::kHitBack;  // classification; shades black
      kernels::store3(rec.normal_kind, ng);
      ++counters.back_faces;
      out[r] = rec;
      continue;
    }
    rec.normal_kind[3] = kernels::kHitFront;
    kernels::store3(rec.normal_kind, ng);
    if (counters.nearest_front < 0.f || hit.t < counters.nearest_front) counters.nearest_front = hit.t;
    const float3 l = path_radiance(ps, origin, dir, hit, key, first, counters, capture);
    kernels::store3(rec.radiance0, l);
    out[r] = rec;
  }
}

namespace {

float3 surface_radiance(const PathSetup& ps, const float3& origin, const float3& n, const float3& ng, const float3& dir,
                        bool traced, const float u[3], uint64_t key, TraceCounters& counters, EndedLight* ended) {
  const bool have_emitters = ps.emitters && !ps.emitters->empty();
  const float3 light =
      have_emitters ? sample_emitter_at(ps, n, ng, float3{1.f, 1.f, 1.f}, origin, u, counters, nullptr) : float3{};
  if (!traced) {
    if (ended) ended->base = light;
    return light;
  }
  const RayMis first = have_emitters ? RayMis{std::max(0.f, kernels::dot(dir, n)) / kernels::kPi, 1.f, 0.f} : RayMis{};
  const float3 along = radiance_along(ps, origin, dir, key, first, counters, ended);
  if (ended) {
    ended->after = light;
    ended->has_after = true;
  }
  return light + along;
}

}  // namespace

float3 EndedLight::resolve(const ProbeField* field) const {
  const float3 v = at_hit ? base + weight * field->irradiance(p, n) * (1.f / kernels::kPi) : base;
  return has_after ? v + after : v;
}

float3 trace_surface_radiance(const PathSetup& ps, const float3& origin, const float3& n, const float3& ng,
                              const float3& dir, bool traced, const float u[3], uint64_t key, TraceCounters& counters,
                              float3* probe_lit) {
  if (!probe_lit) return surface_radiance(ps, origin, n, ng, dir, traced, u, key, counters, nullptr);
  EndedLight ended;
  const float3 l = surface_radiance(ps, origin, n, ng, dir, traced, u, key, counters, &ended);
  *probe_lit = ended.resolve(ps.probe_field);
  return l;
}

float3 trace_surface_radiance_ended(const PathSetup& ps, const float3& origin, const float3& n, const float3& ng,
                                    const float3& dir, bool traced, const float u[3], uint64_t key,
                                    TraceCounters& counters, EndedLight& ended) {
  return surface_radiance(ps, origin, n, ng, dir, traced, u, key, counters, &ended);
}

float3 trace_radiance(const PathSetup& ps, const float3& origin, const float3& dir, uint64_t key,
                      TraceCounters& counters) {
  return radiance_along(ps, origin, dir, key, RayMis{}, counters);
}

bool trace_radiance_within(const PathSetup& ps, const float3& origin, const float3& dir, float tmax, uint64_t key,
                           TraceCounters& counters, float3& out, bool& back_face) {
  const TraceHit hit = ps.trace.prepared->intersect(origin, dir, 0.f, tmax);
  ++counters.rays;
  if (hit.t < 0.f) return false;
  back_face = !hit.front && !hit_material(ps.trace.prepared->scene(), hit).double_sided;
  out = path_radiance(ps, origin, dir, hit, key, RayMis{}, counters, nullptr);
  return true;
}

PathSetup make_path_setup(const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                          const EmitterTable& emitters, uint64_t seed, int bounces) {
  PathSetup path;
  path.trace.prepared = &prepared;
  path.trace.sky = &sky;
  path.trace.lights = lights.data();
  path.trace.light_count = int(lights.size());
  path.trace.seed = seed;
  path.emitters = &emitters;
  path.bounces = bounces;
  return path;
}

}  // namespace gibake
