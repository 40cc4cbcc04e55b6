// Kept paths ended in a probe field (ended_path_hits.h).
#include "bake/preview/ended_path_hits.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "bake/preview/reconstruction_check.h"
#include "bake/run/arena.h"

namespace gibake {

void end_kept_paths(const EndedPathHits& kept, const ProbeField& field, const Context& ctx,
                    std::vector<SurfaceLight>& out) {
  std::unique_ptr<tbb::task_arena> arena = make_arena(ctx);
  arena->execute([&] {
    tbb::parallel_for(size_t(0), kept.points.size(), [&](size_t i) {
      const EndedPathHits::Point& pt = kept.points[i];
      if (pt.rays == 0) return;
      kernels::float3 sum = pt.base;
      double half_lum[2] = {pt.base_half_lum[0], pt.base_half_lum[1]};
      for (const EndedPathHits::Hit& h : pt.hits) {
        const kernels::float3 l = kept_hit_light(h, field);
        sum += l;
        half_lum[h.half] += luminance(l);
      }
      SurfaceLight& o = out[i];
      o.probe_lit = sum * (kernels::kPi / float(pt.rays));
      for (int h = 0; h < 2; ++h)
        o.probe_half[h] = float(kernels::kPi * half_lum[h] / double(std::max(1u, pt.half_count[h])));
    });
  });
}

}  // namespace gibake
