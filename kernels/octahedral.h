// Octahedral direction mapping and probe-atlas addressing (RTXGI layout, DdgiResult docs).
// A tile is (interior+2)^2 texels: a 1-texel border that copies the interior so bilinear
// sampling across the octahedron's folded edges is seamless.
#pragma once
#include <cmath>

#include "kernels/vec.h"

namespace gibake::kernels {

// Unit direction -> [-1,1]^2 and back (DDGI's encode_oct / decode_oct).
inline void encode_oct(const float3& d, float& u, float& v);
float3 decode_oct(float u, float v);

// Direction through the centre of interior texel (tx, ty) of a res x res tile.
float3 oct_texel_direction(int tx, int ty, int res);

// Interior texel containing direction d.
inline void oct_texel_of(const float3& d, int res, int& tx, int& ty);

// Atlas of probes with tiles of interior `res`: with k = planes_per_row (0 means Y), probe
// (x,y,z) is the tile at column x + X*(y mod k), row z + Z*(y div k) (docs/FORMAT.md).
struct AtlasLayout {
  int counts[3] = {1, 1, 1};
  int res = 8;
  int planes_per_row = 0;
  int tile() const { return res + 2; }
  int planes() const { return planes_per_row > 0 ? planes_per_row : counts[1]; }
  int bands() const { return (counts[1] + planes() - 1) / planes(); }
  int width() const { return counts[0] * planes() * tile(); }
  int height() const { return counts[2] * bands() * tile(); }
  // Top-left texel (border included) of the probe with linear index x + X*(y + Y*z).
  void tile_origin(int probe, int& ox, int& oy) const;
};

// The k for AtlasLayout::planes_per_row that keeps an atlas of `tile`-texel tiles at most
// `max_width` wide (when even one plane per row fits), using as few bands as possible and spreading
// the Y planes evenly over them.
int atlas_planes_per_row(int x_count, int y_count, int tile, int max_width);

// Copies interior texels into the tile's border (RTXGI rules: edges mirrored, corners from the
// opposite corner). `atlas` has `channels` floats per texel and row pitch width*channels.
void oct_fill_border(float* atlas, int width, int channels, int ox, int oy, int res);

// Bilinear sample of a probe tile at direction d (inside the tile, using the border); the _uv
// form takes encode_oct(d) already computed.
inline void oct_sample_bilinear(const float* atlas, int width, int channels, int ox, int oy, int res,
                                const float3& d, float* out);


// Inline definitions (hot in the depth integration and the probe-weight loops).
inline float oct_sign_not_zero(float v) { return v >= 0.f ? 1.f : -1.f; }

inline void encode_oct(const float3& d, float& u, float& v) {
  const float inv = 1.f / (std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z));
  float px = d.x * inv, py = d.y * inv;
  if (d.z < 0.f) {
    const float nx = (1.f - std::fabs(py)) * oct_sign_not_zero(px);
    const float ny = (1.f - std::fabs(px)) * oct_sign_not_zero(py);
    px = nx;
    py = ny;
  }
  u = px;
  v = py;
}

inline void oct_texel_of(const float3& d, int res, int& tx, int& ty) {
  float u, v;
  encode_oct(d, u, v);
  tx = static_cast<int>((u * 0.5f + 0.5f) * static_cast<float>(res));
  ty = static_cast<int>((v * 0.5f + 0.5f) * static_cast<float>(res));
  tx = tx < 0 ? 0 : (tx >= res ? res - 1 : tx);
  ty = ty < 0 ? 0 : (ty >= res ? res - 1 : ty);
}

inline void oct_sample_bilinear_uv(const float* atlas, int width, int channels, int ox, int oy, int res, float u,
                                   float v, float* out) {
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

inline void oct_sample_bilinear(const float* atlas, int width, int channels, int ox, int oy, int res,
                                const float3& d, float* out) {
  float u, v;
  encode_oct(d, u, v);
  oct_sample_bilinear_uv(atlas, width, channels, ox, oy, res, u, v, out);
}

}  // namespace gibake::kernels
