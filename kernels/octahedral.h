// Octahedral direction mapping and probe-atlas addressing (RTXGI layout, DdgiResult docs).
// A tile is (interior+2)^2 texels: a 1-texel border that copies the interior so bilinear
// sampling across the octahedron's folded edges is seamless.
#pragma once
#include "kernels/vec.h"

namespace gibake::kernels {

// Unit direction -> [-1,1]^2 and back (the seeds' encode_oct / decode_oct).
void encode_oct(const float3& d, float& u, float& v);
float3 decode_oct(float u, float v);

// Direction through the centre of interior texel (tx, ty) of a res x res tile.
float3 oct_texel_direction(int tx, int ty, int res);

// Interior texel containing direction d.
void oct_texel_of(const float3& d, int res, int& tx, int& ty);

// Atlas of probes with tiles of interior `res`: probe (x,y,z) at column x + X*y, row z.
struct AtlasLayout {
  int counts[3] = {1, 1, 1};
  int res = 8;
  int tile() const { return res + 2; }
  int width() const { return counts[0] * counts[1] * tile(); }
  int height() const { return counts[2] * tile(); }
  // Top-left texel (border included) of the probe with linear index x + X*(y + Y*z).
  void tile_origin(int probe, int& ox, int& oy) const;
};

// Copies interior texels into the tile's border (RTXGI rules: edges mirrored, corners from the
// opposite corner). `atlas` has `channels` floats per texel and row pitch width*channels.
void oct_fill_border(float* atlas, int width, int channels, int ox, int oy, int res);

// Bilinear sample of a probe tile at direction d (inside the tile, using the border).
void oct_sample_bilinear(const float* atlas, int width, int channels, int ox, int oy, int res,
                         const float3& d, float* out);

}  // namespace gibake::kernels
