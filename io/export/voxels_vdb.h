// `gibake scene.gltf --voxels scene.vdb`: the voxelized scene (io/results/voxel_grid.h) as one OpenVDB
// file with named grids, for OpenVDB's tools (vdb_print, python3-openvdb) and Blender.
//
//   density   FloatGrid  coverage 0..1 of surface voxels (fog volume)
//   albedo    Vec3SGrid  average linear base colour
//   emission  Vec3SGrid  average emitted radiance, cd/m^2
//   normal    Vec3SGrid  average unit normal
//   direct    Vec3SGrid  direct irradiance from the scene's lights, lux
//   aniso_px, aniso_nx, aniso_py, aniso_ny, aniso_pz, aniso_nz  FloatGrid  face weights (surface share facing each way)
//   sdf       FloatGrid  level set class: signed distance in metres, negative inside; every voxel
//                        of the grid is active (the whole field, not only a narrow band)
//   interior  FloatGrid  1 in Interior space (enclosed, unreachable from outside), else inactive
//
// With --vxgi too (vxgi_vdb_grids below), per voxel-GI clipmap k (0 = finest), level 0 on the
// voxel-GI grid (its own transform, --vxgi-res), the names `gibake export --vdb` gives them:
//   vxgi<k>_px, vxgi<k>_nx, vxgi<k>_py, vxgi<k>_ny, vxgi<k>_pz, vxgi<k>_nz  Vec3SGrid  radiance
//                        (cd/m^2, not premultiplied) leaving each voxel through that face
//   vxgi<k>_alpha        FloatGrid  opacity, the largest alpha over the six faces
//
// Transform: OpenVDB's index (i,j,k) is gibake's voxel (i,j,k), and OpenVDB puts index points at
// voxel centres, so the transform is scale(voxel_size) then translate(origin + 0.5 * voxel_size):
// voxel (i,j,k)'s centre is at origin + (ijk + 0.5) * voxel_size. File metadata: gibake:origin,
// gibake:voxel_size, gibake:dims, gibake:settings (JSON), gibake:units, gibake:scene.
// Written atomically (temporary file in the target folder, then rename); never over an input.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/export/dense_grid.h"
#include "io/results/voxel_grid.h"
#include "io/results/vxgi_result.h"
#include "io/status.h"

namespace gibake {

struct VoxelVdbOptions {
  std::string settings_json;        // stored as gibake:settings
  std::string scene;                // stored as gibake:scene
  std::vector<std::string> inputs;  // files the output must not replace (the scene and its buffers)
};

// The names write_voxels_vdb gives its own grids (extra grids must use other names).
const std::vector<std::string>& voxel_vdb_grid_names();

// The voxel-GI grids above, as extra grids for write_voxels_vdb (level 0 of every clipmap).
std::vector<DenseGridExport> vxgi_vdb_grids(const VxgiResult& vxgi);

Status write_voxels_vdb(const std::string& path, const VoxelGrid& grid, const std::vector<DenseGridExport>& extra,
                        const VoxelVdbOptions& options);

}  // namespace gibake
