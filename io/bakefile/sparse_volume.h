// A DDGI volume stored sparse (format 1.5): only the probes a sampler reads, each at a slot, the
// atlases' tiles in slot order (docs/FORMAT.md "Sparse volumes").
#pragma once
#include <cstdint>
#include <vector>

#include "io/results/ddgi_result.h"

namespace gibake {

struct SparseVolume {
  DdgiResult result;            // the stored probes' SH, offsets, states, stats and atlases
  std::vector<uint32_t> slots;  // per probe of the grid: its slot, or GIBAKE_PROBE_SLOT_NONE
  uint32_t stored = 0;          // probes with a slot
  uint32_t tiles_per_row = 0;   // atlas tiles a row (T)
};

// The sparse form of `r`: every probe that is not Inactive gets a slot, in probe-index order; the
// atlas rows hold as many tiles as `r`'s rows did (so the atlases stay within the width the bake
// chose), fewer when fewer are stored. False (and `out` untouched) when no probe would be stored:
// the format needs one, and such a volume stays dense.
bool make_sparse_volume(const DdgiResult& r, SparseVolume& out);

}  // namespace gibake
