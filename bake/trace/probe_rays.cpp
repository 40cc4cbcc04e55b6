#include "bake/trace/probe_rays.h"

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
void record_ray(std::vector<CapturedRay>* capture, const float3& o, const float3& d, float tnear, float tfar,
                uint32_t kind) {
  if (capture) capture->push_back(CapturedRay{{o.x, o.y, o.z}, {d.x, d.y, d.z}, tnear, tfar, kind});
}

// A shadow ray's reach towards its light sample: just short of a light at a distance, unbounded
// for a directional one.
float shadow_tfar(const kernels::LightSample& s) {
  return std::isinf(s.distance) ? std::numeric_limits<float>::infinity() : s.distance * (1.f - 1e-4f);
}

}  // namespace

float3 offset_origin(const TraceSetup& setup, const float3& p, const float3& ng) {
  const float pmag = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.f});
  return p + ng * (setup.shadow_bias * pmag);
}

float3 transmittance(const TraceSetup& setup, const float3& org, const float3& dir, float tfar) {
  const PreparedScene& prepared = *setup.prepared;
  if (!prepared.has_transmission()) return prepared.occluded(org, dir, 0.f, tfar) ? float3{} : float3{1.f, 1.f, 1.f};
  float3 through{1.f, 1.f, 1.f};
  float tnear = 0.f;
  for (int crossing = 0; crossing <= kMaxGlassCrossings; ++crossing) {
    const TraceHit hit = prepared.intersect(org, dir, tnear, tfar);
    if (hit.t < 0.f) return through;
    const Material& m = hit_material(prepared.scene(), hit);
    if (!(m.transmission > 0.f) || crossing == kMaxGlassCrossings) return {};
    const SurfaceSample s = hit_surface(prepared.scene(), hit, TextureFootprint{});
    through = through * s.albedo * s.transmission;
    if (kernels::max_component(through) <= 0.f) return {};
    // Past this surface: the offset rays leaving a surface take, along the ray.
    const float3 p = org + dir * hit.t;
    tnear = hit.t + setup.shadow_bias * std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.f});
    if (!(tnear < tfar)) return through;
  }
  return {};
}

void cast_punctual(const TraceSetup& setup, const float3& shadow_org, const float3& n, const float3& ng, float u_choice,
                   PunctualRays& out) {
  out.count = 0;
  out.scale = 1.f;
  const int max_lights = setup.light_count;
  if (max_lights <= 0) return;
  if (max_lights > PunctualRays::kStackLights) {
    out.heap_samples.resize(size_t(max_lights));
    out.heap_visibility.resize(size_t(max_lights));
  }
  kernels::LightSample* samples = out.samples();
  float* visibility = out.visibility();
  auto add_light = [&](int li) {
    kernels::LightSample s;
    if (!kernels::sample_light(setup.lights[li], shadow_org, s)) return;
    if (kernels::dot(n, s.to_light) <= 0.f || kernels::dot(ng, s.to_light) <= 0.f) return;
    const float tfar = shadow_tfar(s);
    bool blocked;
    if (setup.prepared->has_transmission()) {  // through glass: the light arrives tinted
      s.illuminance = s.illuminance * transmittance(setup, shadow_org, s.to_light, tfar);
      blocked = kernels::max_component(s.illuminance) <= 0.f;
    } else {
      blocked = setup.prepared->occluded(shadow_org, s.to_light, 0.f, tfar);
    }
    samples[out.count] = s;
    visibility[out.count] = blocked ? 0.f : 1.f;
    ++out.count;
  };
  if (setup.random_light && max_lights > 1) {
    add_light(std::min(max_lights - 1, static_cast<int>(u_choice * max_lights)));
    out.scale = static_cast<float>(max_lights);
  } else {
    for (int li = 0; li < max_lights; ++li) add_light(li);
  }
}

float3 shade_cast(const TraceSetup& setup, const PunctualRays& rays, const float3& shadow_org, const float3& n,
                  const float3& albedo, const float3& emission, TraceCounters& counters,
                  std::vector<CapturedRay>* capture) {
  // A black surface reflects nothing: its rays, if cast, are not counted (shade_punctual casts none).
  if (setup.light_count <= 0 || kernels::dot(albedo, albedo) <= 0.f) return emission;
  for (int i = 0; i < rays.count; ++i) {
    ++counters.shadow_rays;
    const kernels::LightSample& s = rays.samples()[i];
    record_ray(capture, shadow_org, s.to_light, 0.f, shadow_tfar(s), CapturedRay::kShadow);
  }
  return kernels::shade_direct(n, albedo, emission, rays.samples(), rays.visibility(), rays.count, rays.scale);
}

float3 shade_punctual(const TraceSetup& setup, const float3& shadow_org, const float3& n, const float3& ng,
                      const float3& albedo, const float3& emission, float u_choice, TraceCounters& counters,
                      std::vector<CapturedRay>* capture) {
  if (setup.light_count <= 0 || kernels::dot(albedo, albedo) <= 0.f) return emission;
  PunctualRays rays;
  cast_punctual(setup, shadow_org, n, ng, u_choice, rays);
  return shade_cast(setup, rays, shadow_org, n, albedo, emission, counters, capture);
}

void trace_probe_rays(const TraceSetup& setup, const float3& origin, uint32_t probe, uint32_t pass, const float* dirs,
                      uint32_t count, HitRecord* out, TraceCounters& counters, std::vector<CapturedRay>* capture) {
  const Scene& scene = setup.prepared->scene();
  const float inf = std::numeric_limits<float>::infinity();
  for (uint32_t r = 0; r < count; ++r) {
    const float3 dir = kernels::load3(dirs + 3 * r);
    HitRecord rec;
    kernels::store3(rec.dir_t, dir);
    const TraceHit hit = setup.prepared->intersect(origin, dir, 0.f, inf);
    record_ray(capture, origin, dir, 0.f, inf, setup.shade ? CapturedRay::kProbe : CapturedRay::kRelocation);
    ++counters.rays;
    if (hit.t < 0.f) {
      rec.dir_t[3] = -1.f;
      rec.normal_kind[3] = kernels::kHitMiss;
      if (setup.shade && setup.sky) kernels::store3(rec.radiance0, setup.sky->radiance(dir));
      out[r] = rec;
      continue;
    }
    rec.dir_t[3] = hit.t;
    const Material& mat = hit_material(scene, hit);
    if (!hit.front && !mat.double_sided) {
      // Inside a single-sided surface: counts as a back face, shades black.
      rec.normal_kind[3] = kernels::kHitBack;
      kernels::store3(rec.normal_kind, -hit.ng);
      ++counters.back_faces;
      out[r] = rec;
      continue;
    }
    rec.normal_kind[3] = kernels::kHitFront;
    if (counters.nearest_front < 0.f || hit.t < counters.nearest_front) counters.nearest_front = hit.t;
    // Geometric normal facing the ray (double-sided back hits flip it).
    const float3 ng = hit.front ? hit.ng : -hit.ng;
    if (!setup.shade) {
      kernels::store3(rec.normal_kind, ng);
      out[r] = rec;
      continue;
    }
    const TextureFootprint fp{setup.lod, setup.cone_spread * hit.t, kernels::dot(dir, ng)};
    SurfaceSample surf = hit_surface(scene, hit, fp);
    // This gather does not continue probe rays: glass reflects only the part it does not let
    // through, (1 - t) x albedo, so no light is made (what it lets through is lost here).
    if (mat.transmission > 0.f) surf.albedo = surf.albedo * (1.f - surf.transmission);
    float3 n = surf.normal;
    if (kernels::dot(n, n) == 0.f) n = ng;
    if (kernels::dot(n, ng) < 0.f) n = -n;  // shading normal on the side the ray came from
    kernels::store3(rec.normal_kind, n);
    kernels::store3(rec.albedo, surf.albedo);
    const float3 shadow_org = offset_origin(setup, origin + dir * hit.t, ng);
    const float u = setup.random_light && setup.light_count > 1
                        ? kernels::rng_uniform(kernels::rng_hash(setup.seed, probe, pass, r), 7)
                        : 0.f;
    const float3 l0 = shade_punctual(setup, shadow_org, n, ng, surf.albedo, surf.emission, u, counters, capture);
    kernels::store3(rec.radiance0, l0);
    out[r] = rec;
  }
}

}  // namespace gibake
