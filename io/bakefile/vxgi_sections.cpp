#include "io/bakefile/vxgi_sections.h"

#include <cmath>
#include <cstring>

#include "gibake/format.h"
#include "gibake/loader.hpp"

namespace gibake {
namespace {

bool all_fit(const VxgiClipmap& c) {
  for (const std::vector<float>& level : c.levels)
    for (float v : level)
      if (std::isfinite(v) && std::fabs(v) > 65504.f) return false;
  return true;
}

void put_half(std::vector<uint8_t>& out, size_t at, float v, size_t& clamped) {
  if (std::isfinite(v) && std::fabs(v) > 65504.f) {
    v = v > 0.f ? 65504.f : -65504.f;
    ++clamped;
  }
  const uint16_t h = loader::float_to_half(v);
  std::memcpy(out.data() + at * 2, &h, 2);
}

}  // namespace

Status encode_vxgi_sections(const VxgiResult& r, uint32_t first_index, bool auto_half, bool force_half,
                            std::vector<EncodedSection>& out, size_t& clamped) {
  auto bad = [](const std::string& what) { return Status::invalid("", "vxgi result", what); };
  if (r.clipmaps.empty() || r.clipmaps.size() > 16) return bad("between 1 and 16 clipmaps expected");
  for (size_t k = 0; k < r.clipmaps.size(); ++k) {
    const VxgiClipmap& c = r.clipmaps[k];
    gibake_vxgi_volume d{};
    for (int a = 0; a < 3; ++a) {
      d.grid_min[a] = c.grid_min[size_t(a)];
      d.dims[a] = c.dims[size_t(a)];
      d.sky[a] = r.sky[size_t(a)];
    }
    d.voxel_size = c.voxel_size;
    d.levels = uint32_t(c.levels.size());
    d.faces = uint32_t(c.faces);
    d.clipmap_index = uint32_t(k);
    d.clipmap_count = uint32_t(r.clipmaps.size());
    d.units = GIBAKE_UNITS_CANDELA_PER_M2;
    d.diffuse_scale = c.diffuse_scale;
    d.calibration_error = c.calibration_error;
    d.calibration_points = c.calibration_points;
    const uint64_t count = loader::vxgi_radiance_count(d) / 1;  // RGBA elements
    uint64_t floats = 0;
    for (const std::vector<float>& level : c.levels) floats += level.size();
    if (c.levels.empty() || floats != count * 4) return bad("radiance size does not match the grid");
    if (!c.sdf.empty() && c.sdf.size() != c.voxel_count()) return bad("sdf size does not match the grid");
    const uint32_t group = first_index + uint32_t(out.size());
    EncodedSection desc{GIBAKE_SECTION_VXGI_VOLUME, GIBAKE_FORMAT_STRUCT, group, 1, std::vector<uint8_t>(sizeof d)};
    std::memcpy(desc.bytes.data(), &d, sizeof d);
    out.push_back(std::move(desc));
    const bool half = force_half || (auto_half && all_fit(c));
    EncodedSection rad{GIBAKE_SECTION_VXGI_RADIANCE, half ? uint32_t(GIBAKE_FORMAT_RGBA16F) : uint32_t(GIBAKE_FORMAT_RGBA32F),
                       group, count, std::vector<uint8_t>(size_t(floats) * (half ? 2 : 4))};
    size_t at = 0;
    for (const std::vector<float>& level : c.levels) {
      if (half)
        for (float v : level) put_half(rad.bytes, at++, v, clamped);
      else {
        std::memcpy(rad.bytes.data() + at * 4, level.data(), level.size() * 4);
        at += level.size();
      }
    }
    out.push_back(std::move(rad));
    if (!c.sdf.empty()) {
      EncodedSection sdf{GIBAKE_SECTION_VXGI_SDF, GIBAKE_FORMAT_F16, group, c.sdf.size(),
                         std::vector<uint8_t>(c.sdf.size() * 2)};
      size_t sdf_clamped = 0;  // distances beyond 65504 m only mean "far"
      for (size_t i = 0; i < c.sdf.size(); ++i) put_half(sdf.bytes, i, c.sdf[i], sdf_clamped);
      out.push_back(std::move(sdf));
    }
  }
  return Status::ok();
}

}  // namespace gibake
