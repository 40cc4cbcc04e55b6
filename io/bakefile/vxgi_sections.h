// The voxel-GI part of the bake file (format 1.3): one vxgi_volume, vxgi_radiance and optional
// vxgi_sdf section per clipmap (docs/FORMAT.md).
#pragma once
#include <cstdint>
#include <vector>

#include "io/results/vxgi_result.h"
#include "io/status.h"

namespace gibake {

struct EncodedSection {
  uint32_t type = 0, format = 0;
  uint32_t group = 0;  // table index of the owning vxgi_volume section
  uint64_t count = 0;
  std::vector<uint8_t> bytes;
};

// Sections for `r`, the first of them at table index `first_index`. Radiance as RGBA16F when every
// value fits float16 (|v| <= 65504) or `half` forces it (clamping), else RGBA32F; the SDF as f16.
// `clamped` counts clamped values.
Status encode_vxgi_sections(const VxgiResult& r, uint32_t first_index, bool auto_half, bool force_half,
                            std::vector<EncodedSection>& out, size_t& clamped);

}  // namespace gibake
