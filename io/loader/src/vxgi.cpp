// Voxel-GI volumes (format 1.3): grouping, validation, texel access and trilinear sampling. The
// cone tracer that reads them is vxgi_cone.cpp.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "gibake/loader.hpp"
#include "section_groups.h"

namespace gibake::loader {
namespace {

using groups::fail;
using groups::label;

constexpr uint32_t kFaces = 6;
constexpr uint32_t kMaxLevels = 13;
constexpr uint64_t kMaxCells = uint64_t(1) << 30;

int32_t halve(int32_t d, uint32_t times) {
  for (uint32_t i = 0; i < times; ++i) d = (d + 1) / 2;
  return d;
}

Error check_desc(const gibake_vxgi_volume& d) {
  uint64_t cells = 1;
  int32_t largest = 1;
  for (int a = 0; a < 3; ++a) {
    if (d.dims[a] < 1 || d.dims[a] > 4096)
      return fail(ErrorCode::BadVolume, "voxel count on axis " + std::to_string(a) + " out of range");
    cells *= uint64_t(d.dims[a]);
    largest = std::max(largest, d.dims[a]);
  }
  if (cells > kMaxCells) return fail(ErrorCode::BadVolume, "more than 2^30 voxels");
  uint32_t full = 1;
  while (halve(largest, full - 1) > 1) ++full;  // levels until every axis is 1
  if (d.levels < 1 || d.levels > std::min(full, kMaxLevels))
    return fail(ErrorCode::BadVolume, "levels " + std::to_string(d.levels) + " out of range 1.." + std::to_string(full));
  if (d.faces != kFaces && d.faces != kFaces + 16)
    return fail(ErrorCode::BadVolume, "faces must be 6, or 22 with the precomputed cone slices");
  if (!(std::isfinite(d.voxel_size) && d.voxel_size > 0.f)) return fail(ErrorCode::BadVolume, "voxel_size invalid");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(d.grid_min[a]) || !std::isfinite(d.grid_min[a] + float(d.dims[a]) * d.voxel_size) ||
        !std::isfinite(d.sky[a]))
      return fail(ErrorCode::BadVolume, "non-finite grid bounds or sky");
  if (d.units != GIBAKE_UNITS_CANDELA_PER_M2) return fail(ErrorCode::BadVolume, "units must be cd/m^2 (1)");
  if (d.flags != 0 || d.reserved != 0) return fail(ErrorCode::BadVolume, "unknown flag bits or reserved word set");
  if (!(std::isfinite(d.diffuse_scale) && d.diffuse_scale > 0.f && d.diffuse_scale < 1e3f))
    return fail(ErrorCode::BadVolume, "diffuse_scale must be a positive factor");
  if (!(std::isfinite(d.calibration_error) && d.calibration_error >= 0.f))
    return fail(ErrorCode::BadVolume, "calibration_error must be >= 0");
  if (d.clipmap_index >= d.clipmap_count) return fail(ErrorCode::BadVolume, "clipmap_index >= clipmap_count");
  return {};
}

float read_float(const uint8_t* base, uint32_t format, uint64_t i) {
  if (format == GIBAKE_FORMAT_F16 || format == GIBAKE_FORMAT_RGBA16F) {
    uint16_t h;
    std::memcpy(&h, base + i * 2, 2);
    return half_to_float(h);
  }
  float v;
  std::memcpy(&v, base + i * 4, 4);
  return v;
}

}  // namespace

uint64_t vxgi_radiance_count(const gibake_vxgi_volume& d) {
  uint64_t total = 0;
  for (uint32_t l = 0; l < d.levels; ++l)
    total += uint64_t(d.faces) * uint64_t(halve(d.dims[0], l)) * uint64_t(halve(d.dims[1], l)) *
             uint64_t(halve(d.dims[2], l));
  return total;
}

Error BakeFile::build_vxgi() {
  std::vector<int64_t> volume_of_section;
  const auto read = [this](uint32_t i, const gibake_section_entry& s, VxgiVolume& v) {
    std::memcpy(&v.desc_, data_ + s.offset, sizeof v.desc_);
    v.section_ = i;
    return check_desc(v.desc_);
  };
  if (Error e = groups::collect(sections_, GIBAKE_SECTION_VXGI_VOLUME, "vxgi_volume", read, vxgi_, volume_of_section))
    return e;
  for (const VxgiVolume& v : vxgi_)
    if (v.desc_.clipmap_count != vxgi_.size())
      return fail(ErrorCode::BadVolume, label(v.section_, "vxgi_volume") + ": clipmap_count " +
                                            std::to_string(v.desc_.clipmap_count) + " but the file has " +
                                            std::to_string(vxgi_.size()) + " volumes");
  for (uint32_t i = 0; i < sections_.size(); ++i) {
    const gibake_section_entry& s = sections_[i];
    if (s.type != GIBAKE_SECTION_VXGI_RADIANCE && s.type != GIBAKE_SECTION_VXGI_SDF) continue;
    const char* name = section_type_name(s.type);
    size_t at = 0;
    if (Error e = groups::member_of(volume_of_section, s, i, name, "a vxgi_volume", at)) return e;
    VxgiVolume& v = vxgi_[at];
    const bool radiance = s.type == GIBAKE_SECTION_VXGI_RADIANCE;
    DdgiVolume::View& view = radiance ? v.radiance_ : v.sdf_;
    if (view.data) return fail(ErrorCode::DuplicateSection, label(i, name) + ": second section for the volume");
    const uint64_t expected = radiance ? vxgi_radiance_count(v.desc_)
                                       : uint64_t(v.desc_.dims[0]) * uint64_t(v.desc_.dims[1]) * uint64_t(v.desc_.dims[2]);
    if (s.count != expected)
      return fail(ErrorCode::BadVolume, label(i, name) + ": count " + std::to_string(s.count) + ", volume needs " +
                                            std::to_string(expected));
    view.data = data_ + s.offset;
    view.format = s.format;
    view.section = i;
  }
  for (const VxgiVolume& v : vxgi_)
    if (!v.radiance_.data)
      return fail(ErrorCode::MissingSection, label(v.section_, "vxgi_volume") + ": no vxgi_radiance section");
  std::sort(vxgi_.begin(), vxgi_.end(), [](const VxgiVolume& a, const VxgiVolume& b) {
    return a.desc_.clipmap_index < b.desc_.clipmap_index;
  });
  for (size_t k = 0; k < vxgi_.size(); ++k)
    if (vxgi_[k].desc_.clipmap_index != k)
      return fail(ErrorCode::BadVolume, label(vxgi_[k].section_, "vxgi_volume") + ": clipmap_index " +
                                            std::to_string(vxgi_[k].desc_.clipmap_index) + " repeated");
  // Clipmaps: the same voxel counts, each twice the voxel size of the previous (the
  // tracer's choice of clipmap relies on it).
  for (size_t k = 1; k < vxgi_.size(); ++k) {
    const gibake_vxgi_volume &fine = vxgi_[k - 1].desc_, &coarse = vxgi_[k].desc_;
    const bool dims = fine.dims[0] == coarse.dims[0] && fine.dims[1] == coarse.dims[1] && fine.dims[2] == coarse.dims[2];
    if (!dims || std::fabs(coarse.voxel_size - 2.f * fine.voxel_size) > 1e-5f * coarse.voxel_size)
      return fail(ErrorCode::BadVolume, label(vxgi_[k].section_, "vxgi_volume") + ": clipmap " + std::to_string(k) +
                                            " is not clipmap " + std::to_string(k - 1) +
                                            " with twice the voxel size and the same voxel counts");
  }
  return {};
}

std::array<int32_t, 3> VxgiVolume::level_dims(uint32_t level) const {
  return {halve(desc_.dims[0], level), halve(desc_.dims[1], level), halve(desc_.dims[2], level)};
}

float VxgiVolume::level_voxel_size(uint32_t level) const { return std::ldexp(desc_.voxel_size, int(level)); }

uint64_t VxgiVolume::level_offset(uint32_t level) const {
  gibake_vxgi_volume d = desc_;
  d.levels = std::min(level, desc_.levels);
  return vxgi_radiance_count(d);
}

Rgba VxgiVolume::texel(uint32_t level, uint32_t face, int32_t x, int32_t y, int32_t z) const {
  if (level >= desc_.levels || face >= desc_.faces || !radiance_.data) return {0.f, 0.f, 0.f, 0.f};
  const std::array<int32_t, 3> d = level_dims(level);
  if (x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]) return {0.f, 0.f, 0.f, 0.f};
  const uint64_t cells = uint64_t(d[0]) * uint64_t(d[1]) * uint64_t(d[2]);
  const uint64_t cell = uint64_t(x) + uint64_t(d[0]) * (uint64_t(y) + uint64_t(d[1]) * uint64_t(z));
  const uint64_t e = level_offset(level) + uint64_t(face) * cells + cell;
  return {read_float(radiance_.data, radiance_.format, e * 4), read_float(radiance_.data, radiance_.format, e * 4 + 1),
          read_float(radiance_.data, radiance_.format, e * 4 + 2), read_float(radiance_.data, radiance_.format, e * 4 + 3)};
}

Rgba VxgiVolume::sample(uint32_t level, uint32_t face, const Vec3& p, const Vec3* dir) const {
  Rgba acc{0.f, 0.f, 0.f, 0.f};
  if (level >= desc_.levels) return acc;
  const float h = level_voxel_size(level);
  const std::array<int32_t, 3> d = level_dims(level);
  int32_t base[3];
  float frac[3];
  for (int a = 0; a < 3; ++a) {  // clamped to the outermost centres, as a GPU's clamp-to-edge sampler
    const float u = (p[size_t(a)] - desc_.grid_min[a]) / h - 0.5f;
    if (!std::isfinite(u)) return acc;
    const float clamped = std::min(std::max(u, 0.f), float(d[size_t(a)] - 1));
    base[a] = std::min(int32_t(clamped), std::max(d[size_t(a)] - 2, 0));
    frac[a] = d[size_t(a)] > 1 ? clamped - float(base[a]) : 0.f;
  }
  Rgba t[8];
  for (int corner = 0; corner < 8; ++corner)
    t[corner] = texel(level, face, base[0] + (corner & 1), base[1] + ((corner >> 1) & 1), base[2] + ((corner >> 2) & 1));
  // Separable interpolation, x then y then z. Along an axis the cone travels nearly along
  // (|dir| >= 0.9), the texel it reaches later is seen through the one it reaches first: its colour
  // is weighted by (1 - alpha of the nearer one), so a wall's texel hides what lies in the texel
  // behind it (plain trilinear blending lets an emitter's light through a wall a few voxels thick,
  // tests/vxgi/vxgi_analytic_test.cpp). Not for oblique axes: there the nearer texel at coarse
  // levels often holds the back of a wall the cone started beside, and hiding behind it would take
  // light the furnace test must keep.
  int n = 8;
  for (int a = 0; a < 3; ++a) {
    const float f = frac[a];
    const float da = dir ? (*dir)[size_t(a)] : 0.f;
    n /= 2;
    for (int i = 0; i < n; ++i) {
      const Rgba lo = t[2 * i], hi = t[2 * i + 1];
      const bool ordered = std::fabs(da) >= 0.9f;
      const Rgba& nearer = da >= 0.f ? lo : hi;
      const float wn = da >= 0.f ? 1.f - f : f, wf = 1.f - wn;
      const Rgba& farther = da >= 0.f ? hi : lo;
      const float seen = ordered ? 1.f - std::min(std::max(nearer[3], 0.f), 1.f) : 1.f;
      Rgba r;
      for (int k = 0; k < 3; ++k) r[size_t(k)] = wn * nearer[size_t(k)] + wf * farther[size_t(k)] * seen;
      r[3] = wn * nearer[3] + wf * farther[3];
      t[i] = r;
    }
  }
  return t[0];
}

Rgba VxgiVolume::sample_cone(float lod, const Vec3& dir, const Vec3& p) const {
  const float top = float(desc_.levels - 1);
  lod = std::min(std::max(lod, 0.f), top);
  const uint32_t l0 = uint32_t(lod);
  const float t = lod - float(l0);
  Rgba acc{0.f, 0.f, 0.f, 0.f};
  for (int a = 0; a < 3; ++a) {
    const float w = dir[size_t(a)] * dir[size_t(a)];
    if (w == 0.f) continue;
    const uint32_t face = uint32_t(2 * a + (dir[size_t(a)] < 0.f ? 0 : 1));  // the face looking back at the cone
    Rgba s = sample(l0, face, p, &dir);
    if (t > 0.f && l0 + 1 < desc_.levels) {
      const Rgba s1 = sample(l0 + 1, face, p, &dir);
      for (int k = 0; k < 4; ++k) s[size_t(k)] += t * (s1[size_t(k)] - s[size_t(k)]);
    }
    for (int k = 0; k < 4; ++k) acc[size_t(k)] += w * s[size_t(k)];
  }
  return acc;
}

Rgba VxgiVolume::sample_slice(float lod, uint32_t face, const Vec3& dir, const Vec3& p) const {
  const float top = float(desc_.levels - 1);
  lod = std::min(std::max(lod, 0.f), top);
  const uint32_t l0 = uint32_t(lod);
  const float t = lod - float(l0);
  Rgba s = sample(l0, face, p, &dir);
  if (t > 0.f && l0 + 1 < desc_.levels) {
    const Rgba s1 = sample(l0 + 1, face, p, &dir);
    for (int k = 0; k < 4; ++k) s[size_t(k)] += t * (s1[size_t(k)] - s[size_t(k)]);
  }
  return s;
}

const std::array<Vec3, 16>& precomputed_cone_directions() {
  static const std::array<Vec3, 16> kDirs = {{{0.57735f, 0.57735f, 0.57735f},
                                              {0.57735f, -0.57735f, -0.57735f},
                                              {-0.57735f, 0.57735f, -0.57735f},
                                              {-0.57735f, -0.57735f, 0.57735f},
                                              {-0.903007f, -0.182696f, -0.388844f},
                                              {-0.903007f, 0.182696f, 0.388844f},
                                              {0.903007f, -0.182696f, 0.388844f},
                                              {0.903007f, 0.182696f, -0.388844f},
                                              {-0.388844f, -0.903007f, -0.182696f},
                                              {0.388844f, -0.903007f, 0.182696f},
                                              {0.388844f, 0.903007f, -0.182696f},
                                              {-0.388844f, 0.903007f, 0.182696f},
                                              {-0.182696f, -0.388844f, -0.903007f},
                                              {0.182696f, 0.388844f, -0.903007f},
                                              {-0.182696f, 0.388844f, 0.903007f},
                                              {0.182696f, -0.388844f, 0.903007f}}};
  return kDirs;
}

float VxgiVolume::sdf(const Vec3& p) const {
  if (!sdf_.data) return 0.f;
  int32_t base[3];
  float frac[3];
  for (int a = 0; a < 3; ++a) {
    const float u = (p[a] - desc_.grid_min[a]) / desc_.voxel_size - 0.5f;
    if (!std::isfinite(u)) return 0.f;
    const float clamped = std::min(std::max(u, 0.f), float(desc_.dims[a] - 1));
    base[a] = std::min(int32_t(clamped), std::max(desc_.dims[a] - 2, 0));
    frac[a] = desc_.dims[a] > 1 ? clamped - float(base[a]) : 0.f;
  }
  float acc = 0.f;
  for (int corner = 0; corner < 8; ++corner) {
    float w = 1.f;
    int64_t cell = 0, stride = 1;
    for (int a = 0; a < 3; ++a) {
      const bool up = (corner >> a) & 1;
      w *= up ? frac[a] : 1.f - frac[a];
      cell += stride * std::min(base[a] + (up ? 1 : 0), desc_.dims[a] - 1);
      stride *= desc_.dims[a];
    }
    if (w != 0.f) acc += w * read_float(sdf_.data, sdf_.format, uint64_t(cell));
  }
  return std::max(acc, 0.f);
}

float VxgiVolume::sdf_texel(int32_t x, int32_t y, int32_t z) const {
  if (!sdf_.data || x < 0 || y < 0 || z < 0 || x >= desc_.dims[0] || y >= desc_.dims[1] || z >= desc_.dims[2]) return 0.f;
  return read_float(sdf_.data, sdf_.format,
                    uint64_t(x) + uint64_t(desc_.dims[0]) * (uint64_t(y) + uint64_t(desc_.dims[1]) * uint64_t(z)));
}

bool VxgiVolume::contains(const Vec3& p) const {
  for (int a = 0; a < 3; ++a) {
    const float lo = desc_.grid_min[a], hi = lo + float(desc_.dims[a]) * desc_.voxel_size;
    if (!(p[size_t(a)] >= lo && p[size_t(a)] <= hi)) return false;
  }
  return true;
}

bool BakeFile::sample_vxgi(const Vec3& p, const Vec3& n, Rgb& out, const ConeOptions& options) const {
  out = {0.f, 0.f, 0.f};
  for (const VxgiVolume& v : vxgi_)
    if (v.contains(p)) {
      out = cone_trace_diffuse(vxgi_, p, n, options);  // all clipmaps, from the finest holding p
      return true;
    }
  return false;
}

}  // namespace gibake::loader
