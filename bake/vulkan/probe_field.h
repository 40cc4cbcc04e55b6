// A bake's DDGI volumes packed for the device's GLSL sampler (kernels/shaders/probe_field.glsl):
// the surface fit's paths end at their first hit in the probes' light on the device as the CPU's
// do through the loader (BakeFile::sample_ddgi), so that both estimates come from one path there.
#pragma once
#include <cstdint>
#include <vector>

#include "gibake/loader.hpp"

namespace gibake {

// The four buffers of probe_field.glsl, in its binding order. Values are the loader's decoded
// ones (f16 converted exactly), so the GLSL sampler reads what the CPU's reads.
struct PackedProbeField {
  // 0: volume count, 1: the index's first word (0xFFFFFFFF without an index), 2: the ranks' first
  // word, 3: 0; then every probe's state (volumes in file order), the ddgi_volume_index payload as
  // stored, and each file volume's rank in ddgi_priority().
  std::vector<uint32_t> words;
  std::vector<float> vec4s;   // every probe's offset (xyz, 0), then every irradiance atlas texel (RGBA)
  std::vector<float> floats;  // every SH coefficient's RGB, padded to an even count, then every depth texel
  // Each volume's GlslDdgiVolume in priority order; engine words: x its first irradiance texel in
  // vec4s, y its first probe, z its first depth texel (pairs of floats after the SH), w its first
  // SH triplet.
  std::vector<loader::GlslDdgiVolume> volumes;
};

// The atlases' rows are decoded in parallel, in the caller's task arena.
PackedProbeField pack_probe_field(const loader::BakeFile& file);

}  // namespace gibake
