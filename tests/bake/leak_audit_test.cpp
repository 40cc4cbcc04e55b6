// The leak audit on a scene whose answer is known by construction (tests/reference/make_scenes.py):
// two rooms share one wall 0.2 m thick at x in [-0.1, 0.1]; the left room is lit (emissive patch,
// sun through a window), the right one closed and dark. Every other wall has no open space behind
// it inside the grid.
#include <gtest/gtest.h>

#include <memory>

#include "bake/ddgi/ddgi.h"
#include "bake/voxel/enclosure.h"
#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/voxel/leak_audit.h"
#include "io/gltf/import.h"
#include "io/results/voxel_grid.h"

namespace gibake {
namespace {

struct TwoRooms {
  Scene scene;
  VoxelGrid voxels;
  std::unique_ptr<PreparedScene> prepared;
};

void load_two_rooms(TwoRooms& t, unsigned threads = 0) {
  Context ctx;
  ctx.threads = threads;
  const std::string path = std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/two_rooms.gltf";
  ASSERT_TRUE(import_scene(path, ImportOptions{}, ctx, t.scene).is_ok());
  ASSERT_TRUE(make_enclosure_voxels(t.scene, setup_settings(DdgiSettings{}), ctx, t.voxels).is_ok());
  ASSERT_TRUE(PreparedScene::create(t.scene, ctx, t.prepared).is_ok());
}

LeakAudit audit(const TwoRooms& t, float spacing, unsigned threads = 0) {
  Context ctx;
  ctx.threads = threads;
  LeakAuditSettings s;
  s.probe_spacing = spacing;
  LeakAudit out;
  EXPECT_TRUE(audit_leaks(t.voxels, *t.prepared, shade_lights(t.scene, {}), s, ctx, out).is_ok());
  return out;
}

TEST(LeakAudit, SharedWallThinnerThanTheSpacingIsTheOneRegion) {
  TwoRooms t;
  load_two_rooms(t);
  ASSERT_FALSE(HasFatalFailure());
  const float h = t.voxels.voxel_size;
  const LeakAudit a = audit(t, 0.4f);
  ASSERT_EQ(a.regions_total, 1u);
  const LeakRegion& r = a.regions[0];
  EXPECT_EQ(r.axis, 0);
  // The wall's voxels: x in [-0.1, 0.1] give or take one voxel (conservative voxelization).
  EXPECT_NEAR(r.min[0], -0.1f, 1.01f * h);
  EXPECT_NEAR(r.max[0], 0.1f, 1.01f * h);
  EXPECT_GE(r.thickness, 0.2f);
  EXPECT_LE(r.thickness, 0.2f + 2.01f * h);
  EXPECT_LT(r.lit_point[0], -0.1f);
  EXPECT_GT(r.dark_point[0], 0.1f);
  EXPECT_TRUE(r.dark_enclosed);
  EXPECT_NE(describe_leak(r, 0.4f).find("wall at x -0.1"), std::string::npos) << describe_leak(r, 0.4f);
}

TEST(LeakAudit, WallThickerThanTheSpacingIsNoRisk) {
  TwoRooms t;
  load_two_rooms(t);
  ASSERT_FALSE(HasFatalFailure());
  const LeakAudit a = audit(t, 0.15f);
  for (const LeakRegion& r : a.regions) ADD_FAILURE() << describe_leak(r, 0.15f);
}

TEST(LeakAudit, WithoutLightNothingIsLitSoNothingLeaks) {
  TwoRooms t;
  load_two_rooms(t);
  ASSERT_FALSE(HasFatalFailure());
  for (Material& m : t.scene.materials) m.emissive_strength = 0.f;
  t.scene.lights.clear();
  auto prepared = std::move(t.prepared);
  ASSERT_TRUE(PreparedScene::create(t.scene, Context{}, t.prepared).is_ok());
  const LeakAudit a = audit(t, 0.4f);
  EXPECT_GT(a.thin_wall_crossings, 0u);  // the wall is still thin
  EXPECT_EQ(a.regions_total, 0u);
}

TEST(LeakAudit, SameRegionsForAnyThreadCount) {
  TwoRooms t;
  load_two_rooms(t);
  ASSERT_FALSE(HasFatalFailure());
  const LeakAudit one = audit(t, 0.4f, 1), two = audit(t, 0.4f, 2);
  EXPECT_EQ(one.leak_voxels, two.leak_voxels);
  EXPECT_EQ(one.rays, two.rays);
  ASSERT_EQ(one.regions.size(), two.regions.size());
  for (size_t i = 0; i < one.regions.size(); ++i) {
    EXPECT_EQ(one.regions[i].voxels, two.regions[i].voxels);
    EXPECT_EQ(one.regions[i].min, two.regions[i].min);
  }
}

}  // namespace
}  // namespace gibake
