// Irradiance at a world point from a baked probe grid (DDGI's ddgi_sample_irradiance):
// trilinear over the 8 surrounding probes, smooth back-face weight, Chebyshev visibility from
// the depth moments, inactive probes skipped, then SH irradiance for the normal.
// Used by the multi-bounce passes with the previous pass's probes.
#pragma once
#include <cstdint>

#include "kernels/vec.h"

namespace gibake::kernels {

struct DdgiVolumeView {
  float grid_min[4] = {0, 0, 0, 0};   // rest position of probe (0,0,0)
  float spacing[4] = {0, 0, 0, 0};    // per axis; 0 on an axis with one probe
  int32_t counts[4] = {1, 1, 1, 0};   // probes per axis; w = SH order
  float params[4] = {0.02f, 0.3f, 0.f, 0.f};  // normal bias (m), smooth back-face blend
  const float* offsets = nullptr;     // probe_count*3 relocation offsets
  const uint8_t* inactive = nullptr;  // probe_count, nonzero = skip
  const float* sh = nullptr;          // probe_count * coefficients * 3, incident radiance
  const float* depth_atlas = nullptr; // RG moments, DdgiResult layout (16x16 interior tiles)
  int32_t depth_width = 0;
  int32_t atlas_planes_per_row = 0;   // AtlasLayout::planes_per_row of depth_atlas (0: Y)
  // Optional: the same tiles stored probe after probe ((res+2)^2 x RG each), used instead of the
  // atlas when set -- the 8 lookups of a sample then touch 8 compact tiles, not atlas rows.
  const float* depth_tiles = nullptr;
  int32_t depth_res = 16;
};

float3 ddgi_sample_irradiance(const DdgiVolumeView& volume, const float3& p, const float3& n);

// The same split in two: the normalised weights of up to 8 probes for (p, n) (they depend only
// on positions, states and depth moments, so bounces can reuse them), then the irradiance from
// those probes' SH. Returns the number of probes written (0: nothing visible).
struct ProbeWeights {
  int32_t probe[8];
  float weight[8];
  int32_t count = 0;
};
ProbeWeights ddgi_probe_weights(const DdgiVolumeView& volume, const float3& p, const float3& n);
float3 ddgi_irradiance_from_weights(const float* sh, int sh_order, const ProbeWeights& w, const float3& n);

}  // namespace gibake::kernels
