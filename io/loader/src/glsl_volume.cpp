// The parameters of the GLSL sampler (gibake/ddgi_sample.glsl) for one DDGI volume.
#include "gibake/loader.hpp"

namespace gibake::loader {

GlslDdgiVolume DdgiVolume::glsl_volume() const {
  GlslDdgiVolume g{};
  for (int a = 0; a < 3; ++a) {
    g.grid_min[a] = desc_.grid_min[a];
    g.spacing[a] = desc_.spacing[a];
    g.counts[a] = desc_.counts[a];
  }
  g.counts[3] = int32_t(desc_.sh_coefficients);
  g.spacing[3] = irradiance_.format == GIBAKE_FORMAT_RGB9E5 ? desc_.irradiance_scale : 0.f;
  g.atlas[0] = desc_.depth_tile;
  g.atlas[1] = desc_.tile_border;
  g.atlas[2] = sparse() ? desc_.atlas_tiles_per_row : atlas_planes_per_row();
  g.atlas[3] = (depth_.data ? 1u : 0u) | (sparse() ? 2u : 0u) | (irradiance_.data ? desc_.irradiance_tile << 8 : 0u);
  g.formats[0] = sh_.format;
  g.formats[1] = states_.data ? states_.format : 0u;
  g.formats[2] = depth_.data ? depth_.format : 0u;
  g.formats[3] = (offsets_.data ? 1u : 0u) | (irradiance_.data ? irradiance_.format << 8 : 0u);
  return g;
}

int32_t DdgiVolume::section_index(uint32_t type) const {
  const View* view = nullptr;
  switch (type) {
    case GIBAKE_SECTION_DDGI_VOLUME: return int32_t(volume_section_);
    case GIBAKE_SECTION_DDGI_SH: view = &sh_; break;
    case GIBAKE_SECTION_DDGI_OFFSETS: view = &offsets_; break;
    case GIBAKE_SECTION_DDGI_STATES: view = &states_; break;
    case GIBAKE_SECTION_DDGI_STATS: view = &stats_; break;
    case GIBAKE_SECTION_DDGI_IRRADIANCE: view = &irradiance_; break;
    case GIBAKE_SECTION_DDGI_DEPTH: view = &depth_; break;
    case GIBAKE_SECTION_DDGI_PROBE_SLOTS:
      view = &slots_;
      break;
    default: return -1;
  }
  return view->data ? int32_t(view->section) : -1;
}

}  // namespace gibake::loader
