// LPV cascades (format 1.2): grouping, validation, element access and the trilinear sampler.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "gibake/loader.hpp"
#include "section_groups.h"

namespace gibake::loader {
namespace {

using groups::fail;
using groups::label;

constexpr uint64_t kMaxLpvCells = uint64_t(1) << 27;
constexpr uint32_t kLpvValuesPerCell = 12;

Error check_desc(const gibake_lpv_cascade& d) {
  uint64_t product = 1;
  for (int a = 0; a < 3; ++a) {
    if (d.dims[a] < 1 || d.dims[a] > 4096)
      return fail(ErrorCode::BadVolume, "cell count on axis " + std::to_string(a) + " out of range");
    product *= uint64_t(d.dims[a]);
  }
  if (product > kMaxLpvCells || product != d.cell_count)
    return fail(ErrorCode::BadVolume, "cell_count " + std::to_string(d.cell_count) + " != product of dims " +
                                          std::to_string(product));
  if (!(std::isfinite(d.cell_size) && d.cell_size > 0.f)) return fail(ErrorCode::BadVolume, "cell_size invalid");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(d.grid_min[a]) || !std::isfinite(d.grid_min[a] + float(d.dims[a]) * d.cell_size))
      return fail(ErrorCode::BadVolume, "non-finite grid bounds");
  if (d.sh_coefficients != 4) return fail(ErrorCode::BadVolume, "sh_coefficients must be 4 (L1)");
  if (d.units != GIBAKE_UNITS_CANDELA) return fail(ErrorCode::BadVolume, "units must be candela (3)");
  if (d.flags & ~GIBAKE_LPV_FLAG_OCCLUSION) return fail(ErrorCode::BadVolume, "unknown flag bits");
  if (d.cascade_index >= d.cascade_count) return fail(ErrorCode::BadVolume, "cascade_index >= cascade_count");
  return {};
}

}  // namespace

Error BakeFile::build_lpv() {
  std::vector<int64_t> cascade_of_section;
  const auto read = [this](uint32_t i, const gibake_section_entry& s, LpvCascade& c) {
    std::memcpy(&c.desc_, data_ + s.offset, sizeof c.desc_);
    c.section_ = i;
    return check_desc(c.desc_);
  };
  if (Error e = groups::collect(sections_, GIBAKE_SECTION_LPV_CASCADE, "lpv_cascade", read, lpv_, cascade_of_section))
    return e;
  for (const LpvCascade& c : lpv_) {
    if (c.desc_.cascade_count != lpv_.size())
      return fail(ErrorCode::BadVolume, label(c.section_, "lpv_cascade") + ": cascade_count " +
                                            std::to_string(c.desc_.cascade_count) + " but the file has " +
                                            std::to_string(lpv_.size()) + " cascades");
  }
  for (uint32_t i = 0; i < sections_.size(); ++i) {
    const gibake_section_entry& s = sections_[i];
    if (s.type != GIBAKE_SECTION_LPV_SH) continue;
    size_t at = 0;
    if (Error e = groups::member_of(cascade_of_section, s, i, "lpv_sh", "an lpv_cascade", at)) return e;
    LpvCascade& c = lpv_[at];
    if (c.sh_.data) return fail(ErrorCode::DuplicateSection, label(i, "lpv_sh") + ": second SH section for the cascade");
    const uint64_t expected = uint64_t(c.desc_.cell_count) * kLpvValuesPerCell;
    if (s.count != expected)
      return fail(ErrorCode::BadVolume, label(i, "lpv_sh") + ": count " + std::to_string(s.count) +
                                            ", cascade needs " + std::to_string(expected));
    c.sh_.data = data_ + s.offset;
    c.sh_.format = s.format;
    c.sh_.section = i;
  }
  for (const LpvCascade& c : lpv_)
    if (!c.sh_.data) return fail(ErrorCode::MissingSection, label(c.section_, "lpv_cascade") + ": no lpv_sh section");
  std::sort(lpv_.begin(), lpv_.end(),
            [](const LpvCascade& a, const LpvCascade& b) { return a.desc_.cascade_index < b.desc_.cascade_index; });
  for (size_t k = 0; k < lpv_.size(); ++k)
    if (lpv_[k].desc_.cascade_index != k)
      return fail(ErrorCode::BadVolume, label(lpv_[k].section_, "lpv_cascade") + ": cascade_index " +
                                            std::to_string(lpv_[k].desc_.cascade_index) + " repeated");
  return {};
}

float LpvCascade::sh(uint32_t cell, uint32_t channel, uint32_t coefficient) const {
  if (!sh_.data || cell >= desc_.cell_count || channel >= 3 || coefficient >= 4) return 0.f;
  const size_t i = size_t(cell) * kLpvValuesPerCell + channel * 4 + coefficient;
  if (sh_.format == GIBAKE_FORMAT_F16) {
    uint16_t h;
    std::memcpy(&h, sh_.data + i * 2, 2);
    return half_to_float(h);
  }
  float v;
  std::memcpy(&v, sh_.data + i * 4, 4);
  return v;
}

void LpvCascade::cell_sh(uint32_t cell, float out[12]) const {
  for (uint32_t k = 0; k < kLpvValuesPerCell; ++k) out[k] = sh(cell, k / 4, k % 4);
}

uint32_t LpvCascade::cell_index(int32_t x, int32_t y, int32_t z) const {
  return uint32_t(x) + uint32_t(desc_.dims[0]) * (uint32_t(y) + uint32_t(desc_.dims[1]) * uint32_t(z));
}

Vec3 LpvCascade::cell_centre(int32_t x, int32_t y, int32_t z) const {
  const float h = desc_.cell_size;
  return {desc_.grid_min[0] + (float(x) + 0.5f) * h, desc_.grid_min[1] + (float(y) + 0.5f) * h,
          desc_.grid_min[2] + (float(z) + 0.5f) * h};
}

bool LpvCascade::contains(const Vec3& p) const {
  for (int a = 0; a < 3; ++a) {
    const float lo = desc_.grid_min[a], hi = lo + float(desc_.dims[a]) * desc_.cell_size;
    if (!(p[a] >= lo && p[a] <= hi)) return false;
  }
  return true;
}

Rgb LpvCascade::irradiance_from_sh(const float s[12], const Vec3& n) const {
  constexpr float kPi = 3.14159265358979f;
  const float y0 = 0.282095f, y1 = 0.488603f;
  const float basis[4] = {kPi * y0, 2.f * kPi / 3.f * y1 * -n[1], 2.f * kPi / 3.f * y1 * -n[2],
                          2.f * kPi / 3.f * y1 * -n[0]};
  const float inv_area = 1.f / (desc_.cell_size * desc_.cell_size);
  Rgb e{0.f, 0.f, 0.f};
  for (int c = 0; c < 3; ++c) {
    float v = 0.f;
    for (int k = 0; k < 4; ++k) v += basis[k] * s[c * 4 + k];
    e[size_t(c)] = std::max(0.f, v * inv_area);
  }
  return e;
}

Rgb LpvCascade::sample_irradiance(const Vec3& p, const Vec3& n) const {
  if (!sh_.data) return {0.f, 0.f, 0.f};
  int32_t base[3];
  float frac[3];
  for (int a = 0; a < 3; ++a) {
    const float u = (p[a] - desc_.grid_min[a]) / desc_.cell_size - 0.5f;
    if (!std::isfinite(u)) return {0.f, 0.f, 0.f};
    const int32_t last = desc_.dims[a] - 1;
    const float clamped = std::min(std::max(u, 0.f), float(last));
    base[a] = std::min(int32_t(clamped), std::max(last - 1, 0));
    frac[a] = last > 0 ? clamped - float(base[a]) : 0.f;
  }
  float acc[12] = {};
  for (int corner = 0; corner < 8; ++corner) {
    float w = 1.f;
    int32_t c[3];
    for (int a = 0; a < 3; ++a) {
      const bool up = (corner >> a) & 1;
      w *= up ? frac[a] : 1.f - frac[a];
      c[a] = std::min(base[a] + (up ? 1 : 0), desc_.dims[a] - 1);
    }
    if (w == 0.f) continue;
    float s[12];
    cell_sh(cell_index(c[0], c[1], c[2]), s);
    for (int k = 0; k < 12; ++k) acc[k] += w * s[k];
  }
  return irradiance_from_sh(acc, n);
}

Rgb BakeFile::sample_lpv(const Vec3& p, const Vec3& n) const {
  for (const LpvCascade& c : lpv_)
    if (c.contains(p)) return c.sample_irradiance(p, n);
  return {0.f, 0.f, 0.f};
}

}  // namespace gibake::loader
