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

// The first surface met from `to` back towards `from`, up to `on_surface` past it: Behind when
// `to` lies on its back side (the probe would have gone through it, or off a surface `from` sat
// on, to its back), Through when `to` is in front of a double-sided surface strictly between the
// two. `dir` and `t` give where the surface was met.
Path path_between(const PreparedScene& scene, const float3& from, const float3& to, float on_surface, float3& dir,
                  float& t) {
  const float3 d = from - to;
  const float len = kernels::length(d);
  if (!(len > 0.f)) return Path::Clear;
  dir = d * (1.f / len);
  const TraceHit hit = scene.intersect(to, dir, 0.f, len + on_surface);
  if (hit.t < 0.f) return Path::Clear;
  t = hit.t;
  if (kernels::dot(dir, hit.ng) > 0.f) return Path::Behind;  // the ray leaves `to` along the winding's normal
  if (hit.t >= len - on_surface) return Path::Clear;       // `from` sat on it, `to` is in front
  return triangle_material(scene.scene(), hit.triangle).double_sided ? Path::Through : Path::Clear;
}

void clamp_offset(const RelocateParams& params, std::array<float, 3>& offset) {
  for (int a = 0; a < 3; ++a) offset[a] = std::clamp(offset[a], -params.max_offset[a], params.max_offset[a]);
}
}  // namespace

bool keep_side(const PreparedScene& scene, const float3& from, const std::array<float, 3>& old_offset,
               const RelocateParams& params, float on_surface, std::array<float, 3>& offset) {
  const float3 rest = from - float3{old_offset[0], old_offset[1], old_offset[2]};
  const auto at = [&](const std::array<float, 3>& o) { return rest + float3{o[0], o[1], o[2]}; };
  float3 dir;
  float t = 0.f;
  const float3 to = at(offset);
  const Path path = path_between(scene, from, to, on_surface, dir, t);
  if (path == Path::Clear) return false;
  if (path == Path::Behind) {
    // Mirrored through the surface met: on its front, as far from it as the move was long.
    const float3 front = to + dir * (t + kernels::length(from - to));
    std::array<float, 3> mirrored{front.x - rest.x, front.y - rest.y, front.z - rest.z};
    clamp_offset(params, mirrored);
    if (path_between(scene, from, at(mirrored), on_surface, dir, t) == Path::Clear) {
      offset = mirrored;
      return true;
    }
  }
  offset = old_offset;
  return true;
}

float on_surface_distance(const float3& p, float threshold) {
  const float magnitude = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.f});
  return std::max(1e-3f * threshold, 64.f * FLT_EPSILON * magnitude);
}

}  // namespace gibake
