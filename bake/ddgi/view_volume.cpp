#include "bake/ddgi/view_volume.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/ddgi/detail_volume.h"
#include "bake/scene/prepare.h"

namespace gibake {

namespace {

using kernels::float3;

// The camera's ray through the centre of pixel (x, y), as PreviewCamera::ray traces it.
float3 pixel_ray(const ViewCamera& c, int x, int y) {
  const float sx = (2.f * (float(x) + 0.5f) / float(kViewWidth) - 1.f) * c.tan_half * c.aspect;
  const float sy = (1.f - 2.f * (float(y) + 0.5f) / float(kViewHeight)) * c.tan_half;
  return kernels::normalize(c.forward + c.right * sx + c.up * sy);
}

std::string box_text(const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  char text[160];
  std::snprintf(text, sizeof text, "(%.3g, %.3g, %.3g) to (%.3g, %.3g, %.3g)", double(lo[0]), double(lo[1]),
                double(lo[2]), double(hi[0]), double(hi[1]), double(hi[2]));
  return text;
}

// The finest spacing of the boxes meeting [lo, hi]; 0 when none does.
float finest_meeting(const std::vector<SpacedBox>& planned, const std::array<float, 3>& lo,
                     const std::array<float, 3>& hi) {
  float finest = 0.f;
  for (const SpacedBox& b : planned) {
    bool meets = b.spacing > 0.f;
    for (int a = 0; a < 3; ++a) meets = meets && b.lo[a] <= hi[a] && lo[a] <= b.hi[a];
    if (meets && (finest == 0.f || b.spacing < finest)) finest = b.spacing;
  }
  return finest;
}

}  // namespace

ViewVolumeDecision decide_view_volume(const PreparedScene& prepared, const ViewCamera& view,
                                      const std::vector<SpacedBox>& planned, float spacing) {
  ViewVolumeDecision d;
  std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (int y = 0; y < kViewHeight; ++y)
    for (int x = 0; x < kViewWidth; ++x) {
      const float3 dir = pixel_ray(view, x, y);
      const TraceHit hit = prepared.intersect(view.eye, dir, 0.f, INFINITY);
      ++d.rays;
      if (hit.t < 0.f) continue;
      ++d.hits;
      const float3 p = view.eye + dir * hit.t;
      const float c[3] = {p.x, p.y, p.z};
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
    }
  if (d.hits == 0) {
    d.text = "--near-camera " + view.name + ": no volume (the view sees no surface)";
    return d;
  }
  // A seen box outside every volume (the hits lie within the scene, the volumes may not cover it)
  // takes the coarsest volume's spacing.
  float base = finest_meeting(planned, lo, hi);
  if (base == 0.f)
    for (const SpacedBox& b : planned) base = std::max(base, b.spacing);
  if (!(base > 0.f)) {
    d.text = "--near-camera " + view.name + ": no volume (no volume to refine)";
    return d;
  }
  d.base_spacing = base;
  for (int a = 0; a < 3; ++a) d.lo[a] = lo[a] - base, d.hi[a] = hi[a] + base;
  d.spacing = spacing > 0.f ? spacing : base / 4.f;
  d.probes = box_grid_probes(d.lo, d.hi, d.spacing);
  while (!(spacing > 0.f) && d.probes > kMaxViewProbes && d.spacing * 2.f < base) {
    d.spacing *= 2.f;
    d.probes = box_grid_probes(d.lo, d.hi, d.spacing);
  }
  d.add = true;
  char why[160];
  if (spacing > 0.f)
    std::snprintf(why, sizeof why, "--near-spacing; the finest volume there is %.3g m", double(base));
  else if (d.spacing * 4.f == base)
    std::snprintf(why, sizeof why, "a quarter of the %.3g m of the finest volume there", double(base));
  else
    std::snprintf(why, sizeof why, "half the %.3g m of the finest volume there: a quarter would pass 1048576 probes",
                  double(base));
  char text[480];
  std::snprintf(text, sizeof text,
                "view volume over %s: the surfaces --near-camera %s sees (%llu of %llu rays hit), at %.3g m (%s), "
                "probes near surfaces only",
                box_text(d.lo, d.hi).c_str(), view.name.c_str(), (unsigned long long)d.hits, (unsigned long long)d.rays,
                double(d.spacing), why);
  d.text = text;
  return d;
}

}  // namespace gibake
