// `gibake export --vdb FILE`: the probe grid as OpenVDB grids, index space = probe coordinates,
// transform = scale(spacing) then translate(grid_min) (a 1-probe axis uses scale 1):
//   irradiance_l0 (Vec3SGrid)  L0 irradiance pi*Y00*L00 per probe (lux): mean over normals
//   offset        (Vec3SGrid)  relocation offsets (m)
//   state         (FloatGrid)  0 active, 1 inactive
// Volume v > 0 gets grid names with the suffix "_v". LPV cascade k (format 1.2), per colour c in
// r, g, b, index space = cell coordinates, voxel centres on cell centres:
//   lpv<k>_<c>_sh0 (FloatGrid)  band-0 coefficient of the radiant-intensity SH (cd)
//   lpv<k>_<c>_sh1 (Vec3SGrid)  band-1 coefficients as a vector (x, y, z) = (c3, c1, c2)
// Voxel-GI volume k (format 1.3), level 0, index space = voxel coordinates:
//   vxgi<k>_px .. vxgi<k>_nz (Vec3SGrid)  radiance leaving each voxel through that face (cd/m^2)
//   vxgi<k>_alpha (FloatGrid)             largest alpha over the faces
// Written atomically.
#pragma once
#include <string>

#include "gibake/loader.hpp"
#include "io/status.h"

namespace gibake {

Status export_vdb(const loader::BakeFile& file, const std::string& path);

}  // namespace gibake
