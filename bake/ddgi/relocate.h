// Probe relocation (as in DDGI): a probe whose front-face hits come closer than `threshold` is
// pushed away. Direction: the DDGI sum over the close rays of -dir * (threshold - depth),
// normalised; distance: threshold - nearest front depth (so a probe next to a plane ends up
// `threshold` from it instead of being shoved by however many rays happened to be close).
// The offset is clamped per axis (max_offset, 45% of the cell) around the rest position.
// A move never takes a probe through a surface (keep_side), and a probe that sits on a surface goes
// to the side its winding faces (leave_surface), wherever rounding put its rays' origin.
#pragma once
#include <array>
#include <cstdint>

#include "kernels/shade.h"

namespace gibake {

class PreparedScene;

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

// Checks the move of a probe from `from` (where its pass's rays left, rest + `old_offset`) to rest +
// `offset` against the surfaces along it, traced from the new position back to `from` and
// `on_surface` beyond (a probe that close to a surface sits on it; rounding decides which side its
// rays leave from). The new position must not lie behind (on the back of the winding of) a surface
// there: a probe on a surface belongs on its front, and one in front must stay there; else the
// new position is reflected through that surface's plane to its front (again for the next surface
// behind which it then lies, at an edge or a corner), within max_offset. Nor may it
// cross a double-sided surface (a single-sided one it may leave through its front: the probe was
// inside geometry). Writes the offset to take (old_offset when no such move exists); returns true
// when it changed `offset`.
bool keep_side(const PreparedScene& scene, const kernels::float3& from, const std::array<float, 3>& old_offset,
               const RelocateParams& params, float on_surface, std::array<float, 3>& offset);

// A probe whose rest position lies on a surface (within `on_surface` of it: one of three short
// segments through it, one along each axis, meets a triangle) has no side its rays reliably leave
// from; it is put a few times `on_surface` in front of the surfaces met (along the sum of their
// winding's normals) before the first pass, which then pushes it to the threshold. Returns true
// when it moved `offset`.
bool leave_surface(const PreparedScene& scene, const kernels::float3& rest, float on_surface,
                   std::array<float, 3>& offset);

// How close to a surface a probe counts as on it: far above the rounding of positions near `p`,
// far below any relocation threshold.
float on_surface_distance(const kernels::float3& p, float threshold);

}  // namespace gibake
