#include "bake/ddgi/depth_tiles.h"

#include <tbb/parallel_for.h>

#include "kernels/octahedral.h"

namespace gibake {

bool valid_depth_tile(int interior) {
  return interior == kDepthTexels || interior == kDepthTexels / 2 || interior == kDepthTexels / 4;
}

namespace {

kernels::AtlasLayout layout_of(const DdgiResult& r, int interior) {
  kernels::AtlasLayout l;
  for (int a = 0; a < 3; ++a) l.counts[a] = r.desc.counts[a];
  l.res = interior;
  l.planes_per_row = r.atlas_planes_per_row;
  return l;
}

}  // namespace

void coarsen_depth_atlas(DdgiResult& result, int interior) {
  if (result.depth_atlas.empty() || interior == result.depth_tile) return;
  const int factor = result.depth_tile / interior;
  const kernels::AtlasLayout from = layout_of(result, result.depth_tile), to = layout_of(result, interior);
  const size_t from_width = size_t(from.width()), to_width = size_t(to.width());
  const float* fine = result.depth_atlas.data();
  std::vector<float> atlas(to_width * size_t(to.height()) * 2, 0.f);
  tbb::parallel_for(0, result.desc.probe_count(), [&](int p) {
    int fx, fy, tx, ty;
    from.tile_origin(p, fx, fy);
    to.tile_origin(p, tx, ty);
    for (int y = 0; y < interior; ++y)
      for (int x = 0; x < interior; ++x) {
        const float* nearest = nullptr;
        for (int j = 0; j < factor; ++j)
          for (int i = 0; i < factor; ++i) {
            const size_t fx_at = size_t(fx + 1 + x * factor + i), fy_at = size_t(fy + 1 + y * factor + j);
            const float* t = fine + (fy_at * from_width + fx_at) * 2;
            if (!nearest || t[0] < nearest[0]) nearest = t;
          }
        float* out = &atlas[(size_t(ty + 1 + y) * to_width + size_t(tx + 1 + x)) * 2];
        out[0] = nearest[0];
        out[1] = nearest[1];
      }
    kernels::oct_fill_border(atlas.data(), to.width(), 2, tx, ty, interior);
  });
  result.depth_atlas.swap(atlas);
  result.depth_width = to.width();
  result.depth_height = to.height();
  result.depth_tile = interior;
}

}  // namespace gibake
