// LPV kernels (see lpv.h).
#include "kernels/lpv.h"

#include <cmath>

namespace gibake::kernels {
namespace {

// One face a source cell sends light through: direction w from the source centre to the face
// centre, solid angle, the direction r the face re-emits into the destination, and the basis
// values used in the gather.
struct LpvFace {
  float3 w, r;
  float solid_angle = 0.f;
  float basis[4] = {0, 0, 0, 0};  // Y(w)
  float lobe[4] = {0, 0, 0, 0};   // lobe(r) / pi
  // r is an axis: lobe(r)/pi = (lobe0, 0, 0, 0) + lobe1 at coefficient lobe_index.
  float lobe0 = 0.f, lobe1 = 0.f;
  int lobe_index = 1;
};

// Propagation direction k (0..5): axis k/2, sign + for even k. faces[k][0] is the facing face,
// [1..4] the side faces.
struct LpvFaceTable {
  LpvFace faces[6][5];
  LpvFaceTable() {
    const float big = 2.f / std::sqrt(5.f), small = 1.f / std::sqrt(5.f);
    for (int k = 0; k < 6; ++k) {
      const int axis = k / 2;
      const float sign = (k % 2 == 0) ? 1.f : -1.f;
      float dv[3] = {0, 0, 0};
      dv[axis] = sign;
      const float3 d = load3(dv);
      for (int f = 0; f < 5; ++f) {
        LpvFace& face = faces[k][f];
        if (f == 0) {
          face.w = d;
          face.r = d;
          face.solid_angle = kLpvFacingSolidAngle;
        } else {
          const int side_axis = (axis + 1 + (f - 1) / 2) % 3;
          float sv[3] = {0, 0, 0};
          sv[side_axis] = ((f - 1) % 2 == 0) ? 1.f : -1.f;
          const float3 s = load3(sv);
          face.w = d * big + s * small;
          face.r = s;
          face.solid_angle = kLpvSideSolidAngle;
        }
        lpv_sh_basis(face.w, face.basis);
        lpv_cosine_lobe(face.r, face.lobe);
        for (float& v : face.lobe) v /= kPi;
        face.lobe0 = face.lobe[0];
        for (int c = 1; c < 4; ++c)
          if (face.lobe[c] != 0.f) {
            face.lobe_index = c;
            face.lobe1 = face.lobe[c];
          }
      }
    }
  }
};

const LpvFaceTable& face_table() {
  static const LpvFaceTable table;
  return table;
}

size_t corner_index(const LpvGrid& g, int x, int y, int z) {
  return size_t(x) + size_t(g.dims[0] + 1) * (size_t(y) + size_t(g.dims[1] + 1) * size_t(z));
}

}  // namespace

bool lpv_vpl_cell(const LpvGrid& grid, const LpvVpl& vpl, int32_t cell[3]) {
  const float h = grid.cell_size();
  if (!(h > 0.f)) return false;
  for (int a = 0; a < 3; ++a) {
    const float p = vpl.position[a] + 0.5f * h * vpl.normal[a];
    const float f = std::floor((p - grid.origin_cell[a]) / h);
    if (!(f >= 0.f) || f >= float(grid.dims[a])) return false;
    cell[a] = int32_t(f);
  }
  return true;
}

size_t lpv_inject(const LpvGrid& grid, const LpvVpl* vpls, size_t count, LpvCell* cells) {
  size_t injected = 0;
  for (size_t i = 0; i < count; ++i) {
    int32_t c[3];
    if (!lpv_vpl_cell(grid, vpls[i], c)) continue;
    float lobe[4];
    lpv_cosine_lobe(normalize(load3(vpls[i].normal)), lobe);
    LpvCell& cell = cells[grid.index(c[0], c[1], c[2])];
    for (int ch = 0; ch < 3; ++ch) {
      const float s = vpls[i].flux[ch] / kPi;
      for (int k = 0; k < 4; ++k) cell.sh[ch][k] += s * lobe[k];
    }
    ++injected;
  }
  return injected;
}

void lpv_geometry_add(const LpvGrid& grid, const int32_t corner[3], float area_fraction, const float3& normal,
                      float* geometry) {
  for (int a = 0; a < 3; ++a)
    if (corner[a] < 0 || corner[a] > grid.dims[a]) return;
  if (!(area_fraction > 0.f)) return;
  const float w = (4.f / 3.f) * std::fmin(area_fraction, 1.f);
  float lobe[4];
  lpv_cosine_lobe(-normal, lobe);
  float* g = geometry + 4 * corner_index(grid, corner[0], corner[1], corner[2]);
  for (int k = 0; k < 4; ++k) g[k] += w * lobe[k];
}

namespace {

// Sum of the 4 geometry corners of one face of `cell` (see lpv_face_transmittance).
void face_corner_sum(const LpvGrid& grid, const float* geometry, const int32_t cell[3], int face_axis, bool max_side,
                     float sum[4]) {
  const int a = face_axis, b = (face_axis + 1) % 3, c = (face_axis + 2) % 3;
  for (int k = 0; k < 4; ++k) sum[k] = 0.f;
  int32_t corner[3];
  corner[a] = cell[a] + (max_side ? 1 : 0);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      corner[b] = cell[b] + i;
      corner[c] = cell[c] + j;
      const float* g = geometry + 4 * corner_index(grid, corner[0], corner[1], corner[2]);
      for (int k = 0; k < 4; ++k) sum[k] += g[k];
    }
}

}  // namespace

float lpv_face_transmittance(const LpvGrid& grid, const float* geometry, const int32_t cell[3], int face_axis,
                             bool max_side, const float3& d) {
  float sum[4];
  face_corner_sum(grid, geometry, cell, face_axis, max_side, sum);
  float y[4];
  lpv_sh_basis(d, y);
  return 1.f - saturate(0.25f * lpv_dot4(sum, y));
}

void lpv_flux_scale(const LpvGrid& grid, const LpvCell* src, float* scale, int z_begin, int z_end) {
  const LpvFaceTable& table = face_table();
  const size_t plane = size_t(grid.dims[0]) * size_t(grid.dims[1]);
  for (size_t i = size_t(z_begin) * plane; i < size_t(z_end) * plane; ++i) {
    const LpvCell& cell = src[i];
    for (int ch = 0; ch < 3; ++ch) {
      const float flux = kLpvSqrt4Pi * cell.sh[ch][0];
      float sent = 0.f;
      if (flux > 0.f)
        for (int k = 0; k < 6; ++k)
          for (int f = 0; f < 5; ++f) {
            const LpvFace& face = table.faces[k][f];
            sent += face.solid_angle * std::fmax(0.f, lpv_dot4(cell.sh[ch], face.basis));
          }
      scale[3 * i + ch] = (flux > 0.f && sent > 0.f) ? flux / sent : 0.f;
    }
  }
}

void lpv_propagate(const LpvGrid& grid, const LpvCell* src, const float* scale, const float* geometry, LpvCell* dst,
                   int z_begin, int z_end) {
  const LpvFaceTable& table = face_table();
  const int X = grid.dims[0], Y = grid.dims[1], Z = grid.dims[2];
  for (int z = z_begin; z < z_end; ++z)
    for (int y = 0; y < Y; ++y)
      for (int x = 0; x < X; ++x) {
        LpvCell out;
        const int32_t cell[3] = {x, y, z};
        for (int k = 0; k < 6; ++k) {
          const int axis = k / 2, sign = (k % 2 == 0) ? 1 : -1;
          int32_t s[3] = {x, y, z};
          s[axis] -= sign;  // the source lies behind the destination along the travel direction
          if (s[0] < 0 || s[1] < 0 || s[2] < 0 || s[0] >= X || s[1] >= Y || s[2] >= Z) continue;
          const size_t si = grid.index(s[0], s[1], s[2]);
          const LpvCell& in = src[si];
          const float* sc = scale + 3 * si;
          if (sc[0] == 0.f && sc[1] == 0.f && sc[2] == 0.f) continue;
          // Shared face: the destination's min face on `axis` when travelling +, else its max face.
          float blocking[4] = {0, 0, 0, 0};
          if (geometry) face_corner_sum(grid, geometry, cell, axis, sign < 0, blocking);
          for (int f = 0; f < 5; ++f) {
            const LpvFace& face = table.faces[k][f];
            // Same as lpv_face_transmittance(grid, geometry, cell, axis, sign < 0, face.w).
            const float t = geometry ? 1.f - saturate(0.25f * lpv_dot4(blocking, face.basis)) : 1.f;
            if (t <= 0.f) continue;
            const float w = face.solid_angle * t;
            for (int ch = 0; ch < 3; ++ch) {
              const float flux = w * std::fmax(0.f, lpv_dot4(in.sh[ch], face.basis)) * sc[ch];
              out.sh[ch][0] += flux * face.lobe0;
              out.sh[ch][face.lobe_index] += flux * face.lobe1;
            }
          }
        }
        dst[grid.index(x, y, z)] = out;
      }
}

void lpv_face_table_export(float out[6 * 5 * 8]) {
  const LpvFaceTable& table = face_table();
  for (int k = 0; k < 6; ++k)
    for (int f = 0; f < 5; ++f) {
      const LpvFace& face = table.faces[k][f];
      float* o = out + (k * 5 + f) * 8;
      for (int c = 0; c < 4; ++c) o[c] = face.basis[c];
      o[4] = face.solid_angle;
      o[5] = face.lobe0;
      o[6] = face.lobe1;
      o[7] = float(face.lobe_index);
    }
}

void lpv_accumulate(LpvCell* acc, const LpvCell* add, size_t begin, size_t end) {
  for (size_t i = begin; i < end; ++i)
    for (int ch = 0; ch < 3; ++ch)
      for (int c = 0; c < 4; ++c) acc[i].sh[ch][c] += add[i].sh[ch][c];
}

double lpv_total_flux(const LpvCell* cells, size_t count, int channel) {
  double total = 0.0;
  for (size_t i = 0; i < count; ++i) total += double(lpv_cell_flux(cells[i], channel));
  return total;
}

float3 lpv_cell_irradiance(const LpvCell& cell, const float3& n, float cell_size) {
  float y[4];
  lpv_sh_basis(-n, y);
  const float inv_area = 1.f / (cell_size * cell_size);
  float e[3];
  for (int ch = 0; ch < 3; ++ch) {
    const float v = kPi * cell.sh[ch][0] * y[0] +
                    (2.f * kPi / 3.f) * (cell.sh[ch][1] * y[1] + cell.sh[ch][2] * y[2] + cell.sh[ch][3] * y[3]);
    e[ch] = std::fmax(0.f, v * inv_area);
  }
  return load3(e);
}

}  // namespace gibake::kernels
