// Light Propagation Volume bake (Crytek-style) on the CPU: virtual point lights from Embree
// rays in place of a reflective shadow map, injection into K nested cascades, geometry volume
// from the voxel grid, propagation with occlusion, accumulation. Math in kernels/lpv.h; units
// and the choices behind them in docs/ARCHITECTURE.md ("LPV").
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bake/run/backend.h"
#include "bake/scene/prepare.h"
#include "io/context.h"
#include "io/export/dense_grid.h"
#include "io/results/lpv_result.h"
#include "io/results/voxel_grid.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/lpv.h"
#include "kernels/shade.h"

namespace gibake {

class LpvDevice;

constexpr int kMaxLpvIterations = 4096;  // cap on --lpv-iterations and on its default

struct LpvSettings {
  int resolution = 32;                // cells on the longest axis of every cascade (4..512)
  int iterations = 0;                 // propagation steps; 0: lpv_default_iterations (resolution^2 / 4)
  int cascades = 1;                   // nested cascades, each twice the extent of the one inside it
  uint32_t vpl_samples = 65536;       // rays per light (directional: a jittered grid over the scene)
  uint32_t emissive_samples = 65536;  // VPLs on emissive triangles (all of them together)
  uint64_t seed = 0;
  bool occlusion = true;                          // use the geometry volume when a voxel grid is given
  uint64_t max_memory_bytes = uint64_t(16) << 30;  // cap on the estimated working set (--max-memory)
  // Vulkan: the propagation runs on the device (bake/vulkan/lpv.h); VPLs, injection and the geometry
  // volume stay on the CPU. Recorded in the settings JSON only when Vulkan ran.
  BackendSettings backend;
};

Status validate_lpv_settings(const LpvSettings& settings);
std::string lpv_settings_json(const LpvSettings& settings, const BackendChoice* ran_on = nullptr);

// Cascade grids over the scene bounds: the outermost ([cascades-1]) covers the bounds with one
// cell of padding per side and `resolution` cells on the longest axis (cubic cells); each inner
// cascade has the same cell counts, half the cell size, and the same centre.
Status lpv_cascade_grids(const Bounds& bounds, const LpvSettings& settings, std::vector<kernels::LpvGrid>& out);

// Propagation steps for `--lpv-iterations 0`: a quarter of the square of the grid's longest axis L,
// at least 1 and at most 4096 (the option's cap). The L1 gather is diffusive, not a wavefront that
// keeps its direction: each step sends part of a cell's flux to its side neighbours (the L1 cosine
// lobe is a third of its peak at 90 degrees) and the side faces re-emit across the travel
// direction, so a source's light spreads like a random walk and after N steps reaches about
// sqrt(N) cells (there about half of the inverse-square irradiance, little beyond). L^2/4 steps
// carry light from the grid's centre to its border. More steps reach further but keep adding the
// light that lingers near the source, so the mid-range grows brighter than inverse-square.
int lpv_default_iterations(const kernels::LpvGrid& grid);

// Virtual point lights: for every light, `vpl_samples` rays find the surfaces it lights
// (directional: a jittered grid over the scene bounds' projection, each ray carrying
// E_perp * area / samples; point: a rotated spherical Fibonacci set, spot: stratified over the
// cone, each carrying E_perp(t) * dOmega * t^2 at its hit), reflected flux = albedo * that; and
// `emissive_samples` points on emissive triangles (by area x emission), flux pi * Le * area per
// side. Deterministic for any thread count.
Status generate_vpls(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                     const LpvSettings& settings, const Context& ctx, std::vector<kernels::LpvVpl>& out,
                     LpvStats& stats);

// Geometry volume of one cascade from the voxel grid (kernels::lpv_geometry_add): each surface
// voxel's coverage x voxel face area and average normal go to the cell corner nearest its centre
// (voxels larger than a cell are split into sub-voxels first). 4 floats per corner.
void lpv_geometry_volume(const VoxelGrid& voxels, const kernels::LpvGrid& grid, std::vector<float>& out);

// Propagates `cells` (the injected light, consumed) for `iterations` steps; `accumulated` gets
// the injected light plus every step. Geometry (may be null) blocks from the second step on.
// `flux_per_step` (optional) receives the total flux per channel after each step (for tests).
Status lpv_propagate_volume(const kernels::LpvGrid& grid, std::vector<kernels::LpvCell> cells, const float* geometry,
                            int iterations, const Context& ctx, std::vector<kernels::LpvCell>& accumulated,
                            std::vector<std::array<double, 3>>* flux_per_step = nullptr);

// The whole stage. `lights` as shade_lights() (bake/scene/lights.h) builds them; `voxels` null means no geometry
// occlusion. With voxels, VPLs whose points 0.5 or 1.5 voxels in front of their surface are Interior
// space (closed off) are dropped, and the geometry volume blocks propagation (settings.occlusion).
// `device`: where the propagation runs, as the assembly chose it (bake/pipeline/devices.h:
// make_lpv_device), `choice` what was chosen (the settings JSON names a Vulkan device).
Status bake_lpv(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                const VoxelGrid* voxels, const LpvSettings& settings, const Context& ctx, LpvResult& out,
                std::unique_ptr<LpvDevice> device, const BackendChoice& choice);
// On the CPU (settings.backend must be the CPU's).
Status bake_lpv(const Scene& scene, const PreparedScene& prepared, const std::vector<kernels::ShadeLight>& lights,
                const VoxelGrid* voxels, const LpvSettings& settings, const Context& ctx, LpvResult& out);

// Per cascade k and colour c in {r, g, b}: "lpv<k>_<c>_sh0" (1 channel: band-0 coefficient, cd)
// and "lpv<k>_<c>_sh1" (3 channels: band-1 coefficients reordered as a vector (x, y, z) =
// (c3, c1, c2), pointing where the light mostly travels).
std::vector<DenseGridExport> lpv_dense_grids(const LpvResult& result);

}  // namespace gibake
