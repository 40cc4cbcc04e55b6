#include "kernels/octahedral.h"

#include <algorithm>
#include <cmath>

namespace gibake::kernels {

float3 decode_oct(float u, float v) {
  float3 d{u, v, 1.f - std::fabs(u) - std::fabs(v)};
  if (d.z < 0.f) {
    const float nx = (1.f - std::fabs(d.y)) * oct_sign_not_zero(d.x);
    const float ny = (1.f - std::fabs(d.x)) * oct_sign_not_zero(d.y);
    d.x = nx;
    d.y = ny;
  }
  return normalize(d);
}

float3 oct_texel_direction(int tx, int ty, int res) {
  const float u = ((static_cast<float>(tx) + 0.5f) / static_cast<float>(res)) * 2.f - 1.f;
  const float v = ((static_cast<float>(ty) + 0.5f) / static_cast<float>(res)) * 2.f - 1.f;
  return decode_oct(u, v);
}

void AtlasLayout::tile_origin(int probe, int& ox, int& oy) const {
  const int x = probe % counts[0];
  const int y = (probe / counts[0]) % counts[1];
  const int z = probe / (counts[0] * counts[1]);
  ox = (x + counts[0] * (y % planes())) * tile();
  oy = (z + counts[2] * (y / planes())) * tile();
}

int atlas_planes_per_row(int x_count, int y_count, int tile, int max_width) {
  const long long plane = static_cast<long long>(x_count) * tile;
  const int fit = static_cast<int>(std::max<long long>(1, std::min<long long>(y_count, max_width / plane)));
  const int bands = (y_count + fit - 1) / fit;
  return (y_count + bands - 1) / bands;
}

void oct_fill_border(float* atlas, int width, int channels, int ox, int oy, int res) {
  auto texel = [&](int x, int y) { return atlas + (static_cast<size_t>(oy + y) * width + (ox + x)) * channels; };
  auto copy = [&](int dx, int dy, int sx, int sy) {
    const float* s = texel(sx, sy);
    float* d = texel(dx, dy);
    for (int c = 0; c < channels; ++c) d[c] = s[c];
  };
  const int n = res;
  for (int i = 1; i <= n; ++i) {
    copy(i, 0, n + 1 - i, 1);          // top row mirrors row 1
    copy(i, n + 1, n + 1 - i, n);      // bottom row mirrors row n
    copy(0, i, 1, n + 1 - i);          // left column mirrors column 1
    copy(n + 1, i, n, n + 1 - i);      // right column mirrors column n
  }
  copy(0, 0, n, n);
  copy(n + 1, 0, 1, n);
  copy(0, n + 1, n, 1);
  copy(n + 1, n + 1, 1, 1);
}

}  // namespace gibake::kernels
