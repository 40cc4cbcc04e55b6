#include "bake/ddgi/relocate.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "bake/scene/material.h"
#include "bake/scene/prepare.h"

namespace gibake {

RelocationSums relocation_sums(const kernels::HitRecord* hits, uint32_t count, float threshold) {
  RelocationSums s;
  s.nearest = threshold;
  for (uint32_t r = 0; r < count; ++r) {
    const kernels::HitRecord& h = hits[r];
    if (h.kind() != kernels::kHitFront) continue;
    const float depth = h.dir_t[3];
    if (depth >= threshold) continue;
    s.close = true;
    s.nearest = std::min(s.nearest, depth);
    for (int a = 0; a < 3; ++a) s.delta[a] -= double(h.dir_t[a]) * (threshold - depth);
  }
  return s;
}

bool apply_relocation(const RelocationSums& s, const RelocateParams& params, std::array<float, 3>& offset) {
  if (params.threshold <= 0.f || !s.close) return false;
  const double* delta = s.delta;
  const double len = std::sqrt(delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]);
  if (len <= 0.0) return false;
  const double step = double(params.threshold) - s.nearest;
  for (int a = 0; a < 3; ++a) {
    const float m = params.max_offset[a];
    offset[a] = std::clamp(static_cast<float>(offset[a] + delta[a] / len * step), -m, m);
  }
  return true;
}

namespace {
using kernels::float3;

enum class Path { Clear, Behind, Through };
constexpr float kGrazing = 1e-4f;  // |cos| below which a ray runs along a surface

// The first surface met from `to` towards `target` (`from`, or `on_surface` past it): Behind when
// `to` lies on its back side (the probe would have gone through it, or off a surface `from` sat
// on, to its back), Through when `to` is in front of a double-sided surface strictly between `to`
// and `from`. `hit_point` and `normal` (the winding's) say where and what was met.
Path path_to(const PreparedScene& scene, const float3& from, const float3& to, const float3& target, float on_surface,
             float3& hit_point, float3& normal) {
  const float3 d = target - to;
  const float len = kernels::length(d);
  if (!(len > 0.f)) return Path::Clear;
  const float3 dir = d * (1.f / len);
  const TraceHit hit = scene.intersect(to, dir, 0.f, len);
  if (hit.t < 0.f) return Path::Clear;
  hit_point = to + dir * hit.t;
  normal = hit.ng;
  // Grazing hits (a ray in the surface's plane) say nothing about sides.
  const float facing = kernels::dot(dir, hit.ng);
  if (facing > kGrazing) return Path::Behind;  // the ray leaves `to` along the winding's normal
  if (facing > -kGrazing || hit.t >= kernels::length(from - to) - 2.f * on_surface) return Path::Clear;
  return hit_material(scene.scene(), hit).double_sided ? Path::Through : Path::Clear;
}

// `to` checked against the surfaces between it and `from`: towards `from` a hair past it along the
// move, and a hair past it along each axis the move went (where `from` sits on an edge, the ray
// along the move can meet the one surface `to` is in front of and miss the one it is behind).
Path path_between(const PreparedScene& scene, const float3& from, const float3& to, float on_surface,
                  float3& hit_point, float3& normal) {
  const float3 back = from - to;
  const float len = kernels::length(back);
  if (!(len > 0.f)) return Path::Clear;
  Path worst = path_to(scene, from, to, from + back * (on_surface / len), on_surface, hit_point, normal);
  if (worst == Path::Behind) return worst;
  const float b[3] = {back.x, back.y, back.z};
  for (int a = 0; a < 3; ++a) {
    if (b[a] == 0.f) continue;
    float3 past = from;
    (a == 0 ? past.x : a == 1 ? past.y : past.z) += b[a] > 0.f ? on_surface : -on_surface;
    float3 h, n;
    const Path p = path_to(scene, from, to, past, on_surface, h, n);
    if (p == Path::Behind) {
      hit_point = h, normal = n;
      return p;
    }
    if (p == Path::Through) worst = p;
  }
  return worst;
}

void clamp_offset(const RelocateParams& params, std::array<float, 3>& offset) {
  for (int a = 0; a < 3; ++a) offset[a] = std::clamp(offset[a], -params.max_offset[a], params.max_offset[a]);
}
}  // namespace

bool keep_side(const PreparedScene& scene, const float3& from, const std::array<float, 3>& old_offset,
               const RelocateParams& params, float on_surface, std::array<float, 3>& offset) {
  const float3 rest = from - float3{old_offset[0], old_offset[1], old_offset[2]};
  std::array<float, 3> o = offset;
  // Behind a surface: reflected through its plane, to its front at the same distance, as often as
  // `from` has surfaces to be behind (an edge two, a corner three).
  for (int tries = 0; tries < 4; ++tries) {
    const float3 to = rest + float3{o[0], o[1], o[2]};
    float3 hit_point, normal;
    const Path path = path_between(scene, from, to, on_surface, hit_point, normal);
    if (path == Path::Clear) {
      if (tries == 0) return false;
      offset = o;
      return true;
    }
    if (path == Path::Through) break;
    const float depth = kernels::dot(hit_point - to, normal);  // how far behind
    const float3 front = to + normal * (depth + std::max(depth, 2.f * on_surface));
    o = {front.x - rest.x, front.y - rest.y, front.z - rest.z};
    clamp_offset(params, o);
  }
  offset = old_offset;
  return true;
}

bool leave_surface(const PreparedScene& scene, const float3& rest, float on_surface, std::array<float, 3>& offset) {
  float3 sum{0.f, 0.f, 0.f};
  for (int a = 0; a < 3; ++a) {
    const float3 axis{a == 0 ? 1.f : 0.f, a == 1 ? 1.f : 0.f, a == 2 ? 1.f : 0.f};
    const TraceHit hit = scene.intersect(rest - axis * on_surface, axis, 0.f, 2.f * on_surface);
    if (hit.t >= 0.f) sum = sum + hit.ng;
  }
  const float len = kernels::length(sum);
  if (!(len > 0.f)) return false;
  const float3 step = sum * (4.f * on_surface / len);
  offset = {offset[0] + step.x, offset[1] + step.y, offset[2] + step.z};
  return true;
}

float on_surface_distance(const float3& p, float threshold) {
  const float magnitude = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.f});
  return std::max(1e-3f * threshold, 64.f * FLT_EPSILON * magnitude);
}

}  // namespace gibake
