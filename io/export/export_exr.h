// `gibake export --exr DIR`: the DDGI atlases and SH coefficients as OpenEXR images (float32).
//   irradiance.exr  R,G,B,A   irradiance atlas (lux), RTXGI tile layout (docs/FORMAT.md)
//   depth.exr       R,G       depth moments: mean hit distance (m), mean squared (m^2)
//   sh.exr          c<i>.R/G/B  one pixel per probe (x + X*y, z), SH coefficient i (cd/m^2)
// Volume v > 0 gets the suffix "_v". Every file is written atomically.
#pragma once
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/status.h"

namespace gibake {

// The files export_exr writes into `dir` for `file`, in the order it writes them.
std::vector<std::string> exr_file_paths(const loader::BakeFile& file, const std::string& dir);

// Creates DIR when its parent exists. `written` (optional) receives the paths written.
Status export_exr(const loader::BakeFile& file, const std::string& dir, std::vector<std::string>* written = nullptr);

}  // namespace gibake
