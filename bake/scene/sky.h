// Radiance for rays that escape the scene: a constant colour, or an equirectangular EXR map.
// Equirect mapping (+Y up): for a unit direction d,
//   u = 0.5 + atan2(d.x, -d.z) / (2 pi)   (u = 0.5, the image centre column, looks along -Z;
//                                          u grows towards +X)
//   v = acos(d.y) / pi                    (v = 0, the top row, is straight up +Y)
// Texels are bilinearly interpolated, wrapping in u and clamping in v. Values are cd/m^2,
// multiplied by `scale`.
#pragma once
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

  kernels::float3 radiance(const kernels::float3& dir) const;
  bool is_black() const;
};

// Reads an equirect map with OpenEXR's RGBA interface (any channel layout it accepts).
Status load_sky_exr(const std::string& path, Sky& sky);

}  // namespace gibake
