// View volumes (--near-camera): fine probes near the surfaces a camera sees.
//
// A grid that interpolates light between probes half a metre apart misses light that changes over
// decimetres (a pillar's shaded face beside a sunlit floor, a curtain's folds); probes a decimetre
// apart near every surface of a large scene cost more than a bake or a file affords. Where a user
// judges the picture from known views, the bake spends those probes where the views look, as
// engines place importance volumes by hand (Unreal's lightmass importance volume, Unity's probe
// volumes), with the box found from the view rather than drawn. The rule, at plan time so that every
// shard sees the same plan:
// * The camera's rays through the centres of a kViewWidth x kViewHeight grid of pixels are traced
//   to their first surface (the seen box: their hit points' box).
// * The base spacing is the finest of the volumes planned before it (the default grid, the detail
//   volume, the given ones) whose cell boxes meet the seen box: the grid that would light those
//   surfaces without it.
// * The volume's box is the seen box grown by the base spacing on every side (a volume reads at
//   full weight only up to its cell box, so the growth keeps every seen surface out of its fade
//   band); its spacing is a quarter of the base, doubled while the box would hold more than
//   kMaxViewProbes probes and the spacing is finer than half the base: a view that sees a whole
//   large scene gets a coarser layer, not a refusal. --near-spacing gives the spacing instead: half
//   the base costs an eighth of the probes and reads less near the surfaces (docs/TUNING.md).
// * Only the probes near surfaces are traced and stored (DdgiSettings::near_surface_reach,
//   kNearSurfaceSpacings of its spacing): the open space in the box is the default grid's.
// * A view that sees no surface adds no volume. Several views give a volume each.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/scene.h"
#include "kernels/vec.h"

namespace gibake {

class PreparedScene;

constexpr int kViewWidth = 320, kViewHeight = 180;      // the rays a view traces, as the check's views
constexpr uint64_t kMaxViewProbes = uint64_t(1) << 20;  // a view volume's probes, at most (before the near test)
constexpr float kMinViewSpacing = 0.01f;                // metres: --near-spacing's floor

// A pinhole camera (the preview's, bake/preview/preview.h): an orthonormal frame, tan(vertical
// fov / 2) and width / height. Its own type, not PreviewCamera: bake/preview reads bake/ddgi, and
// the folders' layers may not loop (scripts/check-bake-layers.sh).
struct ViewCamera {
  std::string name;  // as the user gave it (--near-camera's VIEW), for the volume's why
  kernels::float3 eye, forward, right, up;
  float tan_half = 0.f, aspect = 1.f;
};

// A box the views' volumes are judged against: a planned volume's cell box and finest spacing.
struct SpacedBox {
  std::array<float, 3> lo{}, hi{};
  float spacing = 0.f;
};

struct ViewVolumeDecision {
  bool add = false;
  std::array<float, 3> lo{}, hi{};  // the volume's box, metres
  float spacing = 0.f;
  float base_spacing = 0.f;  // the finest spacing among the volumes meeting the seen box
  uint64_t probes = 0;       // the box's probes at that spacing, before the near test
  uint64_t hits = 0, rays = 0;
  std::string text;  // what was placed and why, one line
};

// `planned`: the volumes planned before it (at least one). `spacing` > 0 (--near-spacing) replaces
// the rule's spacing, with no probe cap of its own (the grid's cap and the memory check judge it).
ViewVolumeDecision decide_view_volume(const PreparedScene& prepared, const ViewCamera& view,
                                      const std::vector<SpacedBox>& planned, float spacing = 0.f);

}  // namespace gibake
