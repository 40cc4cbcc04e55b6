#include "kernels/octahedral.h"

#include <cmath>

namespace gibake::kernels {

static float sign_not_zero(float v) { return v >= 0.f ? 1.f : -1.f; }

void encode_oct(const float3& d, float& u, float& v) {
  const float inv = 1.f / (std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z));
  float px = d.x * inv, py = d.y * inv;
  if (d.z < 0.f) {
    const float nx = (1.f - std::fabs(py)) * sign_not_zero(px);
    const float ny = (1.f - std::fabs(px)) * sign_not_zero(py);
    px = nx;
    py = ny;
  }
  u = px;
  v = py;
}

float3 decode_oct(float u, float v) {
  float3 d{u, v, 1.f - std::fabs(u) - std::fabs(v)};
  if (d.z < 0.f) {
    const float nx = (1.f - std::fabs(d.y)) * sign_not_zero(d.x);
    const float ny = (1.f - std::fabs(d.x)) * sign_not_zero(d.y);
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

void oct_texel_of(const float3& d, int res, int& tx, int& ty) {
  float u, v;
  encode_oct(d, u, v);
  tx = static_cast<int>((u * 0.5f + 0.5f) * static_cast<float>(res));
  ty = static_cast<int>((v * 0.5f + 0.5f) * static_cast<float>(res));
  tx = tx < 0 ? 0 : (tx >= res ? res - 1 : tx);
  ty = ty < 0 ? 0 : (ty >= res ? res - 1 : ty);
}

void AtlasLayout::tile_origin(int probe, int& ox, int& oy) const {
  const int x = probe % counts[0];
  const int y = (probe / counts[0]) % counts[1];
  const int z = probe / (counts[0] * counts[1]);
  ox = (x + counts[0] * y) * tile();
  oy = z * tile();
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

void oct_sample_bilinear(const float* atlas, int width, int channels, int ox, int oy, int res,
                         const float3& d, float* out) {
  float u, v;
  encode_oct(d, u, v);
  // Texel-space coordinate inside the tile (border texel 0), texel centres at +0.5.
  const float fx = 1.f + (u * 0.5f + 0.5f) * static_cast<float>(res) - 0.5f;
  const float fy = 1.f + (v * 0.5f + 0.5f) * static_cast<float>(res) - 0.5f;
  int x0 = static_cast<int>(std::floor(fx));
  int y0 = static_cast<int>(std::floor(fy));
  x0 = x0 < 0 ? 0 : (x0 > res ? res : x0);
  y0 = y0 < 0 ? 0 : (y0 > res ? res : y0);
  const float ax = clampf(fx - static_cast<float>(x0), 0.f, 1.f);
  const float ay = clampf(fy - static_cast<float>(y0), 0.f, 1.f);
  auto at = [&](int x, int y) { return atlas + (static_cast<size_t>(oy + y) * width + (ox + x)) * channels; };
  const float* t00 = at(x0, y0);
  const float* t10 = at(x0 + 1, y0);
  const float* t01 = at(x0, y0 + 1);
  const float* t11 = at(x0 + 1, y0 + 1);
  for (int c = 0; c < channels; ++c) {
    const float a = t00[c] + (t10[c] - t00[c]) * ax;
    const float b = t01[c] + (t11[c] - t01[c]) * ax;
    out[c] = a + (b - a) * ay;
  }
}

}  // namespace gibake::kernels
