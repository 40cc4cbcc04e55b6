// Light Propagation Volume kernels (Crytek-style): L1 SH, cosine lobes, VPL injection, geometry
// volume, the 6-neighbour x 5-face propagation gather with occlusion, accumulation and the
// irradiance a cell gives a surface. Plain data, std430-friendly (vec4-aligned), mirrored by the
// Vulkan compute shaders (kernels/shaders/lpv_*.comp). Every function is deterministic: no atomics,
// fixed summation order.
//
// Units (docs/ARCHITECTURE.md, "LPV"): a cell holds the L1 SH of the radiant intensity I(w) (cd =
// lm/sr) of the light inside it, w the direction the light TRAVELS. Its flux is
// integral I dw = sqrt(4 pi) * c0 (lm). A surface with unit normal n near the cell receives
// E(n) = [pi c0 Y00 + 2pi/3 sum_m c1m Y1m(-n)] / h^2 (lux), h the cell size: I/h^2 is the
// radiance of a cell seen as a surface of area h^2 (Kaplanyan 2009).
#pragma once
#include <cstddef>
#include <cstdint>

#include "kernels/vec.h"

namespace gibake::kernels {

constexpr float kLpvY0 = 0.282095f;       // Y00
constexpr float kLpvY1 = 0.488603f;       // Y1m / direction component
constexpr float kLpvLobe0 = 0.886226925f; // sqrt(pi)/2: SH of max(0, n.w), band 0
constexpr float kLpvLobe1 = 1.02332671f;  // sqrt(pi/3): band 1, times n (project order y, z, x)
constexpr float kLpvSqrt4Pi = 3.5449077f; // flux = sqrt(4 pi) * c0
// Solid angles (sr) of a destination cell's far face and of each side face, seen
// from the source cell's centre; 6 x (facing + 4 x side) = 4 pi.
constexpr float kLpvFacingSolidAngle = 0.4006696846f;
constexpr float kLpvSideSolidAngle = 0.4234413544f;

// L1 basis in the project convention: Y00, Y1-1 (y), Y10 (z), Y11 (x).
inline void lpv_sh_basis(const float3& d, float out[4]) {
  out[0] = kLpvY0;
  out[1] = kLpvY1 * d.y;
  out[2] = kLpvY1 * d.z;
  out[3] = kLpvY1 * d.x;
}
// SH of the clamped cosine lobe max(0, n.w) around n (n need not be unit: a shorter n gives a
// less directional lobe, the band-0 term stays).
inline void lpv_cosine_lobe(const float3& n, float out[4]) {
  out[0] = kLpvLobe0;
  out[1] = kLpvLobe1 * n.y;
  out[2] = kLpvLobe1 * n.z;
  out[3] = kLpvLobe1 * n.x;
}
inline float lpv_dot4(const float* a, const float* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

// One cell: radiant-intensity SH per colour channel (R, G, B x 4 coefficients), 48 bytes.
struct LpvCell {
  float sh[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
};
static_assert(sizeof(LpvCell) == 48, "LpvCell is 3 x vec4");

// Grid: cell (x,y,z) covers [origin + (x,y,z)*h, +h), linear index x + X*(y + Y*z).
struct LpvGrid {
  float origin_cell[4] = {0, 0, 0, 1};  // xyz: min corner (m); w: cell size h (m)
  int32_t dims[4] = {0, 0, 0, 0};       // xyz: cells per axis; w: 0
  size_t cells() const { return size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]); }
  size_t index(int x, int y, int z) const { return size_t(x) + size_t(dims[0]) * (size_t(y) + size_t(dims[1]) * size_t(z)); }
  float cell_size() const { return origin_cell[3]; }
};

// A virtual point light: a Lambertian emitter of flux Phi (lm per channel) at a surface point,
// radiant intensity I(w) = Phi/pi * max(0, n.w).
struct LpvVpl {
  float position[4] = {0, 0, 0, 0};  // xyz world position (m)
  float normal[4] = {0, 1, 0, 0};    // xyz unit surface normal (the side the light leaves)
  float flux[4] = {0, 0, 0, 0};      // rgb lumens
};

// Cell a VPL is injected into: the cell containing p + n*h/2 (half a cell along n avoids self-lighting).
// False when that point lies outside the grid.
bool lpv_vpl_cell(const LpvGrid& grid, const LpvVpl& vpl, int32_t cell[3]);

// Adds every VPL that falls into the grid, in array order: cell += Phi/pi * lobe(n). Returns the
// number injected.
size_t lpv_inject(const LpvGrid& grid, const LpvVpl* vpls, size_t count, LpvCell* cells);

// Geometry volume: one L1 SH of the blocking potential B(d) per cell CORNER (dims+1 per axis,
// corner (i,j,k) at origin + (i,j,k)*h), d the direction light travels; B = 1 means opaque.
// A surface of area A with normal n inside a corner's cell-sized footprint adds
// (4/3) * min(1, A/h^2) * lobe(-n): it blocks light travelling into its front face (the L1 lobe
// peaks at 3/4, hence 4/3 so a full face blocks completely).
inline size_t lpv_geometry_corners(const LpvGrid& g) {
  return size_t(g.dims[0] + 1) * size_t(g.dims[1] + 1) * size_t(g.dims[2] + 1);
}
void lpv_geometry_add(const LpvGrid& grid, const int32_t corner[3], float area_fraction, const float3& normal,
                      float* geometry);

// Transmittance of light travelling along d through one face of `cell` (face_axis 0..2;
// max_side false: the face at the cell's min corner on that axis, true: the opposite face),
// from the mean of the face's 4 geometry corners: 1 - saturate(B(d)).
float lpv_face_transmittance(const LpvGrid& grid, const float* geometry, const int32_t cell[3], int face_axis,
                             bool max_side, const float3& d);

// Per cell and channel, the factor that makes the clamped face fluxes sum to the cell's flux:
// sqrt(4 pi) c0 / sum_f dOmega_f max(0, I(w_f)) over the 30 faces a cell sends light through
// (0 for cells without positive flux). Cells z in [z_begin, z_end); writes 3 floats per cell.
void lpv_flux_scale(const LpvGrid& grid, const LpvCell* src, float* scale, int z_begin, int z_end);

// One propagation step for destination cells z in [z_begin, z_end): gathers from the 6
// neighbours, each sending through the 5 faces of the destination that do not touch it
// (solid angles above) the flux dOmega_f * max(0, I_src(w_f)) * scale_src, times the face's
// transmittance when `geometry` is given, re-emitted as a cosine lobe (flux/pi * lobe(r_f)) from
// the destination centre towards that face. dst is overwritten (double buffering).
void lpv_propagate(const LpvGrid& grid, const LpvCell* src, const float* scale, const float* geometry, LpvCell* dst,
                   int z_begin, int z_end);

// The propagation's face table for GPU kernels: 6 directions x 5 faces, 8 floats each: Y(w) (4),
// solid angle, lobe0, lobe1, lobe_index (as float), in lpv_propagate's (k, f) order.
void lpv_face_table_export(float out[6 * 5 * 8]);

// acc += add for cells [begin, end).
void lpv_accumulate(LpvCell* acc, const LpvCell* add, size_t begin, size_t end);

// Flux (lm) of one channel of a cell, sqrt(4 pi) c0, and of a whole grid (in index order).
inline float lpv_cell_flux(const LpvCell& c, int channel) { return kLpvSqrt4Pi * c.sh[channel][0]; }
double lpv_total_flux(const LpvCell* cells, size_t count, int channel);

// Irradiance (lux, clamped >= 0) on a surface with unit normal n from one cell's SH:
// E = [pi c0 Y00 + 2pi/3 c1 . Y1(-n)] / h^2.
float3 lpv_cell_irradiance(const LpvCell& cell, const float3& n, float cell_size);

}  // namespace gibake::kernels
