// Voxel-GI bake (voxel cone tracing with clipmaps and anisotropic mips): the scene voxelized at
// --vxgi-res, and for every occupied voxel and each of its six faces the radiance leaving it,
// computed with the path tracer (all bounces), opacity from coverage, closed interiors opaque, then
// the anisotropic mip chain. Layout and face convention: io/results/vxgi_result.h,
// bake/vxgi/vxgi_mips.h, docs/FORMAT.md.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/scene/prepare.h"
#include "bake/scene/sky.h"
#include "io/context.h"
#include "io/results/voxel_grid.h"
#include "io/results/vxgi_result.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake {

// The format's 4096 voxels an axis less the voxelizer's padding (a voxel each side and one more).
constexpr int kMaxVxgiResolution = 4093;

struct VxgiSettings {
  int resolution = 64;          // voxels on the longest axis of the scene bounds (4..kMaxVxgiResolution)
  int bounces = 4;              // path vertices after the voxel's own surface (as --bounces)
  uint32_t rays = 64;           // rays per voxel face
  uint64_t seed = 0;
  bool sdf = true;              // store the empty-space distance (vxgi_sdf) for SDF-accelerated cones
  float blend_cutoff = 0.5f;    // as the other bakes
  uint64_t max_bytes = uint64_t(16) << 30;  // cap on the estimated working set (--max-memory)
  uint32_t calibration_points = 256;  // surface points for the diffuse_scale fit (0: no fit, scale 1)
  uint32_t calibration_rays = 256;    // path-traced rays per calibration point
  // Clipmaps: `clipmaps` volumes of the same voxel counts, the coarsest over the scene
  // bounds at `resolution`, each finer one half the voxel size and half the extent of the next,
  // centred on `center` (or on the scene's centre) snapped to its own voxels.
  int clipmaps = 1;  // 1..8
  bool precompute_cones = false;  // the 16 precomputed cone directions as slices beside the six faces
  // Each side of a surface stored in the voxel on that side (bake/vxgi/vxgi_radiance.cpp): no voxel
  // holds the mean of a thin wall's two sides. Off (the default, --vxgi-sides mixed): each surface
  // voxel holds what its faces see. Opt-in because it pays only at some resolutions (BENCHMARKS.md).
  bool split_sides = false;
  // With split sides and one volume: the grid's origin moved down by up to 2^align_levels - 1
  // voxels per axis so that double-sided walls' two layers stay in separate texels up to that mip
  // level (vxgi_wall_alignment); 0 (the default): no move. Opt-in: the added empty voxels upset the
  // calibration fit at coarse resolutions (docs/BENCHMARKS.md).
  int align_levels = 0;
  bool has_center = false;
  std::array<float, 3> center{0.f, 0.f, 0.f};  // metres
};

Status validate_vxgi_settings(const VxgiSettings& settings);
std::string vxgi_settings_json(const VxgiSettings& settings);

// Level-0 grid of the coarsest clipmap and estimated working set (the voxelizer of the finest
// clipmap's voxel size over the whole scene + every clipmap's float mip chain, file payload and
// SDF), without allocating anything; BadArguments with the figure when it exceeds settings.max_bytes.
Status plan_vxgi(const Scene& scene, const VxgiSettings& settings, VoxelGrid& layout, uint64_t& estimated_bytes);

// Radiance of level 0 from a voxel grid (layout of vxgi_result.h). For face f of a surface voxel,
// `rays` rays enter the voxel through that face (origins uniform over it, directions cosine-
// distributed about the inward axis) and the path tracer gives the radiance leaving whatever they
// hit inside the voxel towards the face: albedo x irradiance / pi + emission at the exact hit,
// back faces of single-sided surfaces black. The face's radiance L is the mean over the hits (over
// the voxel's other faces' hits when none of this face's rays hit), its alpha the voxel's
// coverage; stored premultiplied. With split_sides each hit's radiance goes instead to the voxel
// half a voxel off the hit on the side the ray saw (vxgi_radiance.cpp says how faces are filled).
// Voxels inside closed solids (vxgi_solid_interior) are
// (0, 0, 0, 1) on every face; faces whose neighbour is Interior are never seen and are not traced. Keys: (seed, voxel, face, ray).
// `stream` keeps the ray keys of different clipmaps apart (0 for the coarsest).
Status vxgi_radiance(const VoxelGrid& grid, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                     const Sky& sky, const VxgiSettings& settings, const Context& ctx, std::vector<float>& level0,
                     VxgiStats& stats, uint32_t stream = 0);

// Clipmap k of `clipmaps` (bake/vxgi/vxgi_clipmaps.cpp): the voxel grid `full` (the whole scene
// voxelized at that clipmap's voxel size) cut to the `dims` voxels around `center`, origin snapped
// to full's voxels. Voxels beyond `full` are empty Exterior.
VoxelGrid vxgi_crop_grid(const VoxelGrid& full, const std::array<float, 3>& center, const std::array<int32_t, 3>& dims);
// A cut clipmap's free distance cannot see geometry beyond its border: each value is capped at the
// distance from the voxel to the border (the tracer then steps no further than the border).
void vxgi_cap_free_distance(std::vector<float>& free, const std::array<int32_t, 3>& dims, float voxel_size);
// The precomputed cone slices: appends to every level of `clip` (6 faces) the 16 slices
// sum_a d_a^2 x (the face facing back at direction d on axis a), d = loader::precomputed_cone_directions().
void vxgi_precompute_cones(VxgiClipmap& clip);
// One clipmap: radiance, SDF and mips of a grid (and the cone slices when asked).
Status vxgi_bake_clipmap(const VoxelGrid& grid, bool cut, uint32_t stream, const PreparedScene& prepared,
                         const std::vector<kernels::ShadeLight>& lights, const Sky& sky, const VxgiSettings& settings,
                         const Context& ctx, VxgiClipmap& clip, VxgiStats& stats);

// Per axis, the voxels to add below `layout` (0 .. 2^levels - 1, the fewest among the best) that
// score best: the sum over double-sided triangles facing along the axis of area x the difference
// of the lights' shadowed direct illuminance on their two sides x the mip level (capped at
// `levels`) up to which the triangle's two voxel layers stay in separate texels (vxgi_align.cpp).
std::array<int32_t, 3> vxgi_wall_alignment(const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                                           const VoxelGrid& layout, int levels);

// Which Interior voxels lie inside closed solids rather than in closed rooms: per 6-connected
// Interior region, the surface voxels around it vote with their normal's component along the step
// out of the region (a solid's surface faces away from its inside, a room's walls face into it).
std::vector<uint8_t> vxgi_solid_interior(const VoxelGrid& grid);

// Distance (m) from each voxel centre to the nearest opaque voxel (alpha > 0 on any face), made
// conservative for trilinear lookups (26-neighbour chamfer / 1.15, minus two voxels, >= 0).
std::vector<float> vxgi_free_distance(const std::vector<float>& level0, const std::array<int32_t, 3>& dims,
                                      float voxel_size);

// Fits the volume's diffuse_scale (bake/vxgi/vxgi_calibrate.cpp): the least-squares factor between
// the loader's diffuse cone trace and the path-traced irradiance at `calibration_points` points in
// open space (two voxels or more from geometry), 14 normals in turn; stores it with the remaining
// relative RMS.
Status vxgi_calibrate(const VoxelGrid& grid, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                      const Sky& sky, const VxgiSettings& settings, const Context& ctx, VxgiResult& result);

// The whole stage: plan (the estimate is printed through ctx.note before anything is allocated),
// voxelize, radiance, mips, SDF, calibration.
Status bake_vxgi(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                 const Sky& sky, const VxgiSettings& settings, const Context& ctx, VxgiResult& out);

}  // namespace gibake
