// View volumes (bake/ddgi/view_volume.h): a camera's first hits, known from the geometry, give the
// box; the spacing follows the rule; the plan adds the volume near surfaces only, after the given
// volumes and before the refined ones. Known by construction: a camera 3.5 m in front of the back
// wall of a room (tests' open_front_room, the wall's face at z = 0, x and y in [0, 4]) with
// tan(fov / 2) = 0.25 sees that wall alone, over 3.5 x 0.25 x (1 - 1/180) m above and below its
// axis and 16/9 of that (times 1 - 1/320) to either side, through the pixels' centres.
#include "bake/ddgi/view_volume.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "bake/ddgi/probe_grid.h"
#include "bake/ddgi/volume_plan.h"
#include "bake/scene/prepare.h"
#include "scene_builders.h"

namespace {

using gibake::ViewCamera;

ViewCamera wall_view() {
  ViewCamera v;
  v.name = "test";
  v.eye = {2.f, 2.f, 3.5f};
  v.forward = {0.f, 0.f, -1.f};
  v.right = {1.f, 0.f, 0.f};
  v.up = {0.f, 1.f, 0.f};
  v.tan_half = 0.25f;
  v.aspect = 16.f / 9.f;
  return v;
}

// One volume over the whole room at `spacing`.
std::vector<gibake::SpacedBox> room_grid(float spacing) { return {{{-1.f, -1.f, -1.f}, {5.f, 5.f, 5.f}, spacing}}; }

std::unique_ptr<gibake::PreparedScene> prepare(const gibake::Scene& scene) {
  std::unique_ptr<gibake::PreparedScene> p;
  EXPECT_TRUE(gibake::PreparedScene::create(scene, gibake::Context{}, p).is_ok());
  return p;
}

TEST(ViewVolume, TheBoxIsTheSeenSurfacesGrownByTheBaseSpacing) {
  const gibake::Scene scene = gibake::test::open_front_room(0.5f);
  const auto prepared = prepare(scene);
  const float base = 0.5f;
  const gibake::ViewVolumeDecision d = gibake::decide_view_volume(*prepared, wall_view(), room_grid(base));
  ASSERT_TRUE(d.add) << d.text;
  EXPECT_EQ(d.rays, uint64_t(gibake::kViewWidth) * gibake::kViewHeight);
  EXPECT_EQ(d.hits, d.rays);
  const float half_h = 3.5f * 0.25f * (1.f - 1.f / 180.f), half_w = 3.5f * 0.25f * 16.f / 9.f * (1.f - 1.f / 320.f);
  const float lo[3] = {2.f - half_w - base, 2.f - half_h - base, -base};
  const float hi[3] = {2.f + half_w + base, 2.f + half_h + base, base};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(d.lo[a], lo[a], 1e-4f) << a;
    EXPECT_NEAR(d.hi[a], hi[a], 1e-4f) << a;
  }
  EXPECT_FLOAT_EQ(d.spacing, base / 4.f);  // a quarter of the default spacing: 26 x 16 x 8 probes
  EXPECT_EQ(d.probes, gibake::box_grid_probes(d.lo, d.hi, d.spacing));
  EXPECT_NE(d.text.find("--near-camera test"), std::string::npos) << d.text;
}

// A box whose quarter-spacing lattice would pass kMaxViewProbes gets half the default spacing.
TEST(ViewVolume, ALargeBoxGetsACoarserSpacing) {
  const gibake::Scene scene = gibake::test::open_front_room(0.5f);
  const auto prepared = prepare(scene);
  const float base = 0.02f;  // a quarter: 0.005 m, about 1.8 million probes over the seen box
  const gibake::ViewVolumeDecision d = gibake::decide_view_volume(*prepared, wall_view(), room_grid(base));
  ASSERT_TRUE(d.add);
  EXPECT_GT(gibake::box_grid_probes(d.lo, d.hi, base / 4.f), gibake::kMaxViewProbes);
  EXPECT_FLOAT_EQ(d.spacing, base / 2.f);
  EXPECT_LE(d.probes, gibake::kMaxViewProbes);
}

// --near-spacing: the given spacing, past the rule's probe cap too (the grid's cap judges it).
TEST(ViewVolume, AGivenSpacingReplacesTheRule) {
  const gibake::Scene scene = gibake::test::open_front_room(0.5f);
  const auto prepared = prepare(scene);
  const gibake::ViewVolumeDecision d = gibake::decide_view_volume(*prepared, wall_view(), room_grid(0.5f), 0.25f);
  ASSERT_TRUE(d.add);
  EXPECT_FLOAT_EQ(d.spacing, 0.25f);
  EXPECT_FLOAT_EQ(d.base_spacing, 0.5f);
  EXPECT_NE(d.text.find("--near-spacing"), std::string::npos) << d.text;
  const gibake::ViewVolumeDecision fine = gibake::decide_view_volume(*prepared, wall_view(), room_grid(0.02f), 0.005f);
  EXPECT_FLOAT_EQ(fine.spacing, 0.005f);
  EXPECT_GT(fine.probes, gibake::kMaxViewProbes);
}

TEST(ViewVolume, AViewOfNothingAddsNoVolume) {
  const gibake::Scene scene = gibake::test::open_front_room(0.5f);
  const auto prepared = prepare(scene);
  ViewCamera away = wall_view();
  away.eye = {2.f, 2.f, 10.f};
  away.forward = {0.f, 0.f, 1.f};
  away.right = {-1.f, 0.f, 0.f};
  const gibake::ViewVolumeDecision d = gibake::decide_view_volume(*prepared, away, room_grid(0.5f));
  EXPECT_FALSE(d.add);
  EXPECT_EQ(d.hits, 0u);
  EXPECT_NE(d.text.find("sees no surface"), std::string::npos) << d.text;
}

// The base spacing is the finest among the volumes that meet the seen box: a finer volume elsewhere
// does not count, one over the wall does.
TEST(ViewVolume, TheBaseIsTheFinestVolumeWhereTheViewLooks) {
  const gibake::Scene scene = gibake::test::open_front_room(0.5f);
  const auto prepared = prepare(scene);
  std::vector<gibake::SpacedBox> volumes = room_grid(0.5f);
  volumes.push_back({{0.f, 0.f, 2.f}, {4.f, 4.f, 4.f}, 0.1f});  // in front of the camera's near plane only
  EXPECT_FLOAT_EQ(gibake::decide_view_volume(*prepared, wall_view(), volumes).base_spacing, 0.5f);
  volumes.push_back({{1.f, 1.f, -0.5f}, {3.f, 3.f, 0.5f}, 0.2f});  // over the seen wall
  const gibake::ViewVolumeDecision d = gibake::decide_view_volume(*prepared, wall_view(), volumes);
  EXPECT_FLOAT_EQ(d.base_spacing, 0.2f);
  EXPECT_FLOAT_EQ(d.spacing, 0.05f);
}

// The plan: the view volume after the given one, before the refined ones, over the decision's box
// at its spacing, its probes near surfaces only, on the default grid's spacing.
TEST(ViewVolume, ThePlanAddsANearVolumeAfterTheGivenOnes) {
  const gibake::Scene scene = gibake::test::open_front_room(0.5f);
  gibake::VolumeSettings vs;
  vs.given.push_back({{0.5f, 0.5f, 0.5f}, {3.5f, 3.5f, 3.5f}, 0.4f});
  vs.views.push_back(wall_view());
  gibake::DdgiSettings s;
  s.suns.push_back({{0.3f, -1.f, -0.2f}, 50000.f, {1.f, 1.f, 1.f}});  // lights the floor: refinement places volumes
  gibake::VolumePlan plan;
  ASSERT_TRUE(gibake::plan_ddgi_volumes(scene, s, vs, gibake::Context{}, plan));
  ASSERT_GE(plan.volumes.size(), 3u);
  EXPECT_EQ(plan.volumes[1].kind, gibake::VolumeKind::Given);
  const gibake::PlannedVolume& view = plan.volumes[2];
  ASSERT_EQ(view.kind, gibake::VolumeKind::View);
  std::vector<gibake::SpacedBox> before;
  for (int i = 0; i < 2; ++i) {  // the default grid and the given volume, as cell boxes
    const gibake::DdgiVolumeDesc& desc = plan.volumes[size_t(i)].placed.desc;
    gibake::SpacedBox b;
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = desc.grid_min[a] - 0.5f * desc.spacing[a];
      b.hi[a] = desc.grid_max[a] + 0.5f * desc.spacing[a];
    }
    b.spacing = gibake::min_cell_size(desc);
    before.push_back(b);
  }
  const auto prepared = prepare(scene);
  const gibake::ViewVolumeDecision d = gibake::decide_view_volume(*prepared, wall_view(), before);
  EXPECT_FLOAT_EQ(d.base_spacing, std::min(before[0].spacing, 0.4f));
  EXPECT_EQ(view.why, d.text);
  EXPECT_FLOAT_EQ(view.placed.desc.spacing[0], d.spacing);
  EXPECT_FLOAT_EQ(view.near_surface_reach, gibake::kNearSurfaceSpacings * d.spacing);
  EXPECT_EQ(uint64_t(view.placed.desc.probe_count()), d.probes);
  for (int a = 0; a < 3; ++a) {  // whole cells over the box, one probe at the centre of each
    const float cell_lo = view.placed.desc.grid_min[a] - 0.5f * d.spacing;
    const float cell_hi = view.placed.desc.grid_max[a] + 0.5f * d.spacing;
    EXPECT_LE(cell_lo, d.lo[a] + 1e-5f) << a;
    EXPECT_GE(cell_hi, d.hi[a] - 1e-5f) << a;
    EXPECT_LT(cell_hi - cell_lo - (d.hi[a] - d.lo[a]), d.spacing) << a;
  }
  EXPECT_GT(plan.volumes.size(), 3u) << "the sun should have refined the floor";
  for (size_t i = 3; i < plan.volumes.size(); ++i) EXPECT_EQ(plan.volumes[i].kind, gibake::VolumeKind::Refined);
}

}  // namespace
