// Virtual point lights for the LPV bake (bake/lpv/lpv.h generate_vpls): rays from every light find
// the surfaces it lights; emissive triangles are sampled by area x emission.
//
// Units: a ray carries a cross-section A (m^2) of the light's beam at the hit (directional:
// the projected bounds' area / samples; point and spot: dOmega * t^2), the illuminance E_perp
// (lux) of a surface facing the light there, so E_perp * A lumens arrive; a Lambertian surface of
// albedo rho reflects rho * E_perp * A lumens (its radiance rho E cos/pi over its footprint A/cos
// integrated over the hemisphere), emitted as I(w) = Phi/pi * max(0, n.w).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "bake/lpv/lpv.h"
#include "bake/scene/material.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

using kernels::float3;
using kernels::LpvVpl;

constexpr uint32_t kChunk = 4096;  // samples per task; fixed so results never depend on threads

// Stream ids of the counter-based generator (rng_hash(seed, light, kPass..., sample)).
constexpr uint64_t kPassDirectional = 0x4c50560001ull;
constexpr uint64_t kPassSpot = 0x4c50560002ull;
constexpr uint64_t kPassPoint = 0x4c50560003ull;
constexpr uint64_t kPassEmissive = 0x4c50560004ull;

float3 any_perpendicular(const float3& d) {
  const float3 a = std::fabs(d.x) < 0.9f ? float3{1.f, 0.f, 0.f} : float3{0.f, 1.f, 0.f};
  return kernels::normalize(kernels::cross(d, a));
}

// A VPL where a ray from a light met a surface, or nothing (miss, back face of a one-sided
// material, black albedo). `beam_area`: the ray's cross-section at the hit (m^2).
bool vpl_at_hit(const Scene& scene, const PreparedScene& prepared, const kernels::ShadeLight& light,
                const float3& org, const float3& dir, float beam_area_per_t2, float beam_area_const, LpvVpl& out) {
  const TraceHit hit = prepared.intersect(org, dir, 0.f, std::numeric_limits<float>::infinity());
  if (hit.t < 0.f) return false;
  const SurfaceSample s = hit_surface(scene, hit, TextureFootprint{});
  if (!hit.front && !s.double_sided) return false;
  const float3 ng = hit.front ? hit.ng : -hit.ng;  // the side the light arrives on
  float3 n = s.normal;
  if (kernels::dot(n, ng) < 0.f) n = -n;
  if (!(kernels::dot(n, n) > 0.5f)) n = ng;
  const float3 p = org + dir * hit.t;
  kernels::LightSample ls;
  if (!kernels::sample_light(light, p, ls)) return false;
  const float area = beam_area_const + beam_area_per_t2 * hit.t * hit.t;
  const float3 flux = s.albedo * ls.illuminance * area;
  if (!(flux.x > 0.f || flux.y > 0.f || flux.z > 0.f)) return false;
  kernels::store3(out.position, p);
  kernels::store3(out.normal, n);
  kernels::store3(out.flux, flux);
  return true;
}

struct Bounds3 {
  float3 lo, hi;
  float3 centre() const { return (lo + hi) * 0.5f; }
  float radius() const { return 0.5f * kernels::length(hi - lo); }
};

// Runs f(sample, vpl&) -> bool for samples [0, n) in fixed chunks; appends the VPLs in sample order.
template <typename F>
void for_samples(tbb::task_arena& arena, uint32_t n, std::vector<LpvVpl>& out, F&& f) {
  const uint32_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<LpvVpl>> parts(chunks);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, chunks, 1), [&](const tbb::blocked_range<uint32_t>& r) {
      for (uint32_t c = r.begin(); c < r.end(); ++c) {
        const uint32_t end = std::min(n, (c + 1) * kChunk);
        for (uint32_t i = c * kChunk; i < end; ++i) {
          LpvVpl v;
          if (f(i, v)) parts[c].push_back(v);
        }
      }
    });
  });
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
}

uint32_t directional_vpls(const Scene& scene, const PreparedScene& prepared, const kernels::ShadeLight& light,
                      uint32_t index, const Bounds3& b, const LpvSettings& s, tbb::task_arena& arena,
                      std::vector<LpvVpl>& out) {
  const float3 d = kernels::normalize(kernels::load3(light.direction_type));
  const float3 u = any_perpendicular(d), v = kernels::cross(d, u);
  float umin = 1e30f, umax = -1e30f, vmin = 1e30f, vmax = -1e30f;
  for (int c = 0; c < 8; ++c) {
    const float3 p{(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z};
    umin = std::min(umin, kernels::dot(p, u));
    umax = std::max(umax, kernels::dot(p, u));
    vmin = std::min(vmin, kernels::dot(p, v));
    vmax = std::max(vmax, kernels::dot(p, v));
  }
  const float pad = 1e-3f * std::max(1.f, b.radius());
  umin -= pad, vmin -= pad, umax += pad, vmax += pad;
  const float wu = umax - umin, wv = vmax - vmin;
  const uint32_t nu = std::clamp<uint32_t>(uint32_t(std::lround(std::sqrt(double(s.vpl_samples) * wu / wv))), 1u,
                                           s.vpl_samples);
  const uint32_t nv = std::max<uint32_t>(1, s.vpl_samples / nu);
  const float cell_area = (wu / float(nu)) * (wv / float(nv));
  const float start = kernels::dot(b.centre(), d) - 2.f * b.radius() - 1.f;
  for_samples(arena, nu * nv, out, [&](uint32_t i, LpvVpl& vpl) {
    const uint64_t key = kernels::rng_hash(s.seed, index, kPassDirectional, i);
    const float a = umin + (float(i % nu) + kernels::rng_uniform(key, 0)) * (wu / float(nu));
    const float c = vmin + (float(i / nu) + kernels::rng_uniform(key, 1)) * (wv / float(nv));
    const float3 org = u * a + v * c + d * start;
    return vpl_at_hit(scene, prepared, light, org, d, 0.f, cell_area, vpl);
  });
  return nu * nv;
}

void point_vpls(const Scene& scene, const PreparedScene& prepared, const kernels::ShadeLight& light, uint32_t index,
                const LpvSettings& s, tbb::task_arena& arena, std::vector<LpvVpl>& out) {
  const float3 org = kernels::load3(light.position_range);
  const uint32_t n = s.vpl_samples;
  std::vector<float> dirs(size_t(n) * 3);
  kernels::generate_probe_rays(s.seed, index, uint32_t(kPassPoint & 0xffff), n, dirs.data());
  const float d_omega = 4.f * kernels::kPi / float(n);
  for_samples(arena, n, out, [&](uint32_t i, LpvVpl& vpl) {
    return vpl_at_hit(scene, prepared, light, org, kernels::load3(&dirs[size_t(i) * 3]), d_omega, 0.f, vpl);
  });
}

uint32_t spot_vpls(const Scene& scene, const PreparedScene& prepared, const kernels::ShadeLight& light, uint32_t index,
               const LpvSettings& s, tbb::task_arena& arena, std::vector<LpvVpl>& out) {
  const float3 org = kernels::load3(light.position_range);
  const float3 axis = kernels::normalize(kernels::load3(light.direction_type));
  const float3 t = any_perpendicular(axis), bt = kernels::cross(axis, t);
  // KHR_lights_punctual: offset = -cos(outer) * scale.
  const float cos_outer = light.cone[0] > 0.f ? kernels::clampf(-light.cone[1] / light.cone[0], -1.f, 1.f) : -1.f;
  const uint32_t n = s.vpl_samples;
  const uint32_t side = std::max<uint32_t>(1, uint32_t(std::sqrt(double(n))));
  const uint32_t total = side * side;  // stratified side x side over (cos theta, phi)
  const float d_omega = 2.f * kernels::kPi * (1.f - cos_outer) / float(total);
  for_samples(arena, total, out, [&](uint32_t i, LpvVpl& vpl) {
    const uint64_t key = kernels::rng_hash(s.seed, index, kPassSpot, i);
    const float u1 = (float(i % side) + kernels::rng_uniform(key, 0)) / float(side);
    const float u2 = (float(i / side) + kernels::rng_uniform(key, 1)) / float(side);
    const float ct = 1.f - u1 * (1.f - cos_outer), st = std::sqrt(std::max(0.f, 1.f - ct * ct));
    const float phi = 2.f * kernels::kPi * u2;
    const float3 dir = axis * ct + t * (st * std::cos(phi)) + bt * (st * std::sin(phi));
    return vpl_at_hit(scene, prepared, light, org, dir, d_omega, 0.f, vpl);
  });
  return total;
}

struct Emitter {
  uint32_t triangle;
  double weight;  // area x max emission channel (upper bound of the texture's emission)
};

void emissive_vpls(const Scene& scene, const LpvSettings& s, tbb::task_arena& arena, std::vector<LpvVpl>& out,
                   uint64_t& count) {
  std::vector<Emitter> emitters;
  std::vector<double> cdf;
  double total = 0.0;
  const size_t tris = scene.indices.size() / 3;
  for (size_t t = 0; t < tris; ++t) {
    const Material& m = triangle_material(scene, uint32_t(t));
    const float e = std::max({m.emissive[0], m.emissive[1], m.emissive[2]}) * m.emissive_strength;
    if (!(e > 0.f)) continue;
    const float3 a = kernels::load3(&scene.positions[3 * size_t(scene.indices[3 * t])]);
    const float3 b = kernels::load3(&scene.positions[3 * size_t(scene.indices[3 * t + 1])]);
    const float3 c = kernels::load3(&scene.positions[3 * size_t(scene.indices[3 * t + 2])]);
    const double area = 0.5 * double(kernels::length(kernels::cross(b - a, c - a)));
    if (!(area > 0.0)) continue;
    total += area * double(e);
    emitters.push_back({uint32_t(t), area * double(e)});
    cdf.push_back(total);
  }
  if (emitters.empty() || s.emissive_samples == 0) return;
  const uint32_t n = s.emissive_samples;
  const size_t before = out.size();
  for_samples(arena, n, out, [&](uint32_t i, LpvVpl& vpl) {
    const uint64_t key = kernels::rng_hash(s.seed, 0, kPassEmissive, i);
    const double xi = (double(i) + double(kernels::rng_uniform(key, 0))) / double(n) * total;
    const size_t k = std::min(emitters.size() - 1, size_t(std::upper_bound(cdf.begin(), cdf.end(), xi) - cdf.begin()));
    const uint32_t t = emitters[k].triangle;
    float r1 = kernels::rng_uniform(key, 1), r2 = kernels::rng_uniform(key, 2);
    const float sq = std::sqrt(r1);
    const float bu = sq * (1.f - r2), bv = sq * r2;  // barycentrics of v1, v2
    const float3 a = kernels::load3(&scene.positions[3 * size_t(scene.indices[3 * t])]);
    const float3 b = kernels::load3(&scene.positions[3 * size_t(scene.indices[3 * t + 1])]);
    const float3 c = kernels::load3(&scene.positions[3 * size_t(scene.indices[3 * t + 2])]);
    const float3 ng = kernels::cross(b - a, c - a);
    const float area = 0.5f * kernels::length(ng);
    const SurfaceSample ss = surface_sample(scene, t, bu, bv);
    // pi * Le * area / (n * p), p = weight / total: each sample's share of the emitted flux.
    const float w = float(kernels::kPi * double(area) * total / (double(n) * emitters[k].weight));
    const float3 flux = ss.emission * w;
    if (!(flux.x > 0.f || flux.y > 0.f || flux.z > 0.f)) return false;
    kernels::store3(vpl.position, a * (1.f - bu - bv) + b * bu + c * bv);
    kernels::store3(vpl.normal, kernels::normalize(ng));
    kernels::store3(vpl.flux, flux);
    vpl.flux[3] = ss.double_sided ? 1.f : 0.f;  // marks a second VPL for the back side
    return true;
  });
  // Double-sided emitters emit from both sides: a mirrored VPL per sample, appended in order.
  const size_t after = out.size();
  for (size_t i = before; i < after; ++i) {
    if (out[i].flux[3] == 0.f) continue;
    out[i].flux[3] = 0.f;
    LpvVpl back = out[i];
    for (int a = 0; a < 3; ++a) back.normal[a] = -back.normal[a];
    out.push_back(back);
  }
  count = out.size() - before;
}

}  // namespace

Status generate_vpls(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                     const LpvSettings& settings, const Context& ctx, std::vector<kernels::LpvVpl>& out,
                     LpvStats& stats) {
  out.clear();
  if (scene.indices.empty()) return Status::ok();
  const Bounds3 b{kernels::load3(scene.bounds.min.data()), kernels::load3(scene.bounds.max.data())};
  std::unique_ptr<tbb::task_arena> arena = ctx.threads > 0
                                               ? std::make_unique<tbb::task_arena>(static_cast<int>(ctx.threads))
                                               : std::make_unique<tbb::task_arena>();
  for (uint32_t i = 0; i < lights.size(); ++i) {
    const kernels::ShadeLight& l = lights[i];
    if (settings.vpl_samples == 0 || !(l.color[0] > 0.f || l.color[1] > 0.f || l.color[2] > 0.f)) continue;
    const int type = static_cast<int>(l.direction_type[3]);
    const size_t before = out.size();
    if (type == kernels::kLightDirectional) {
      stats.vpl_rays += directional_vpls(scene, prepared, l, i, b, settings, *arena, out);
    } else if (type == kernels::kLightSpot) {
      stats.vpl_rays += spot_vpls(scene, prepared, l, i, settings, *arena, out);
    } else {
      point_vpls(scene, prepared, l, i, settings, *arena, out);
      stats.vpl_rays += settings.vpl_samples;
    }
    stats.vpls += out.size() - before;
    ctx.report("lpv vpls", double(i + 1), double(lights.size() + 1));
  }
  emissive_vpls(scene, settings, *arena, out, stats.emissive_vpls);
  for (const LpvVpl& v : out)
    for (int c = 0; c < 3; ++c) stats.vpl_flux[c] += double(v.flux[c]);
  return Status::ok();
}

}  // namespace gibake
