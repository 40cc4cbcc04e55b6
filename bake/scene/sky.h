// Radiance for rays that escape the scene: a constant colour, or an equirectangular EXR map.
// Equirect mapping (+Y up): for a unit direction d,
//   u = 0.5 + atan2(d.x, -d.z) / (2 pi)   (u = 0.5, the image centre column, looks along -Z;
//                                          u grows towards +X)
//   v = acos(d.y) / pi                    (v = 0, the top row, is straight up +Y)
// Texels are bilinearly interpolated, wrapping in u and clamping in v. Values are cd/m^2,
// multiplied by `scale`.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/status.h"
#include "kernels/vec.h"

namespace gibake {

struct Sky {
  kernels::float3 constant;  // used when no map is loaded
  int width = 0, height = 0;
  std::vector<float> rgb;  // width*height*3, linear
  float scale = 1.f;
  // Values of the map that were NaN, infinite or negative, read as 0 (load_sky_exr): its caller
  // says how many, since such a map lights the scene less than its author meant.
  uint64_t replaced_values = 0;

  // Importance sampling of the map (build_sky_sampling; empty: none): the (u, v) cell of texel
  // (x, y) is chosen with probability proportional to the largest luminance of the texel and its 8
  // neighbours (the bilinear lookup's radiance in the cell never exceeds it) x sin(theta at its
  // centre), then a point uniformly in the cell. row_cdf: inclusive prefix sums over
  // rows (height, last 1); col_cdf: per row, inclusive prefix sums over its texels (height x width,
  // each row's last 1; rows of weight 0 are uniform).
  std::vector<float> row_cdf, col_cdf;

  kernels::float3 radiance(const kernels::float3& dir) const;
  bool is_black() const;
  bool sampled() const { return !row_cdf.empty(); }
  // A direction from three uniforms (row, column; the remainders place it in the texel) and its
  // solid-angle density; pdf(d) is that density for any direction.
  kernels::float3 sample(float u_row, float u_col, float& pdf) const;
  float pdf(const kernels::float3& dir) const;
};

// Reads an equirect map (R, G, B as 32-bit floats; a Y or YC file through OpenEXR's RGBA interface)
// and builds its sampling tables. A file that is not a regular one is an I/O error; one without
// colour channels is invalid.
Status load_sky_exr(const std::string& path, Sky& sky);
// The sampling tables of sky.rgb (none for a black map or a constant sky).
void build_sky_sampling(Sky& sky);

}  // namespace gibake
