// Probe relocation (as in DDGI): a probe whose front-face hits come closer than `threshold` is
// pushed away. Direction: the DDGI sum over the close rays of -dir * (threshold - depth),
// normalised; distance: threshold - nearest front depth (so a probe next to a plane ends up
// `threshold` from it instead of being shoved by however many rays happened to be close).
// The offset is clamped per axis (max_offset, 45% of the cell) around the rest position.
#pragma once
#include <array>
#include <cstdint>

#include "kernels/shade.h"

namespace gibake {

struct RelocateParams {
  float threshold = 0.f;              // metres (fraction x min cell size)
  std::array<float, 3> max_offset{};  // per-axis clamp (metres)
};

// What the move reads of one batch of records: the sum over front hits nearer than the threshold
// of -dir * (threshold - depth) (in double, rays in order), the nearest such depth, whether there
// was one. Made on the CPU from records (relocation_sums) or on a Vulkan device
// (kernels/shaders/reloc_sums.comp) without the records crossing the bus.
struct RelocationSums {
  double delta[3] = {0, 0, 0};
  float nearest = 0.f;  // the threshold when !close
  bool close = false;
};

// The sums of one batch of records traced at rest + offset.
RelocationSums relocation_sums(const kernels::HitRecord* hits, uint32_t count, float threshold);
// Moves `offset` by the sums (the direction of delta, threshold - nearest, clamped to max_offset).
// Returns true when moved.
bool apply_relocation(const RelocationSums& sums, const RelocateParams& params, std::array<float, 3>& offset);

}  // namespace gibake
