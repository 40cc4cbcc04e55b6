// The GLSL sampler tests' engine-side arrays: a DDGI volume's decoded SH, states, offsets, depth
// moments and irradiance atlas texels, appended as an engine would upload them (the accessor kernels
// read these).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "gibake/loader.hpp"

namespace gibake::test {

struct DecodedDdgi {
  std::vector<float> sh, offsets, depth, irradiance;  // irradiance: RGBA per texel (lux)
  std::vector<uint32_t> states;
  std::vector<uint32_t> slots;  // per probe of the grid: its stored index (a sparse volume's map)
  bool sh_of_nine = false;      // every probe's SH padded to 9 coefficients (one index for all data)

  // Per stored probe, in slot order (every probe of a dense volume, in probe order).
  void append(const loader::DdgiVolume& v) {
    const gibake_ddgi_volume& d = v.desc();
    for (uint32_t p = 0; p < v.probe_count(); ++p) {
      slots.push_back(v.slot(p));
      if (v.slot(p) == GIBAKE_PROBE_SLOT_NONE) continue;
      for (uint32_t c = 0; c < (sh_of_nine ? 9u : v.sh_coefficients()); ++c)
        for (uint32_t k = 0; k < 3; ++k) sh.push_back(c < v.sh_coefficients() ? v.sh(p, c, k) : 0.f);
      states.push_back(v.state(p));
      const loader::Vec3 o = v.offset(p);
      offsets.insert(offsets.end(), {o[0], o[1], o[2], 0.f});
    }
    for (uint32_t y = 0; y < d.depth_height; ++y)
      for (uint32_t x = 0; x < d.depth_width; ++x) {
        const std::array<float, 2> t = v.depth_texel(x, y);
        depth.insert(depth.end(), {t[0], t[1]});
      }
    for (uint32_t y = 0; y < d.irradiance_height; ++y)
      for (uint32_t x = 0; x < d.irradiance_width; ++x) {
        // As stored: an RGB9E5 texel before its irradiance_scale, which the sampler applies.
        std::array<float, 4> t = v.irradiance_texel(x, y);
        const float scale = v.glsl_volume().spacing[3];
        for (int k = 0; k < 3 && scale > 0.f; ++k) t[size_t(k)] /= scale;  // exact: a power of two
        irradiance.insert(irradiance.end(), t.begin(), t.end());
      }
  }
};

}  // namespace gibake::test
