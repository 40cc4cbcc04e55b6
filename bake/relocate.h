// Probe relocation (seed 001): a probe whose front-face hits come closer than `threshold` is
// pushed away. Direction: the seed's sum over the close rays of -dir * (threshold - depth),
// normalised; distance: threshold - nearest front depth (so a probe next to a plane ends up
// `threshold` from it instead of being shoved by however many rays happened to be close).
// The offset is clamped per axis (max_offset, 45% of the cell) around the rest position.
#pragma once
#include <array>
#include <cstdint>

#include "kernels/shade.h"

namespace gibake {

struct RelocateParams {
  float threshold = 0.f;                  // metres (fraction x min cell size)
  std::array<float, 3> max_offset{};      // per-axis clamp (metres)
};

// Updates `offset` from one batch of records traced at rest + offset. Returns true when moved.
bool relocate_probe(const kernels::HitRecord* hits, uint32_t count, const RelocateParams& params,
                    std::array<float, 3>& offset);

}  // namespace gibake
