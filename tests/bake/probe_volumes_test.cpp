// The automatic detail volume (bake/ddgi/detail_volume.h) on scenes whose answer is known by
// construction: the house on a ground plane 20 times its size (tests/volumes/make_house.py: an
// 8 x 3.2 x 6 m house, x in [-4, 4], z in [-3, 3], on a 160 m ground) gets a detail volume around
// the house at the rule's spacing for an 8 m model (8 / 16 = 0.5 m, up to one 1.25 m voxel wider
// on each side: at most 10.5 / 16 = 0.66 m), while scenes one grid serves (the bundled sample,
// two_rooms, cornell-box-nvpro when present) and a bare ground plane get none; box grids keep their
// spacing exactly.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <filesystem>

#include "bake/ddgi/detail_volume.h"
#include "bake/ddgi/probe_grid.h"
#include "bake/voxel/enclosure.h"
#include "io/gltf/import.h"
#include "scene_builders.h"

namespace {

using gibake::DdgiVolumeDesc;
using gibake::DetailDecision;
using gibake::GridSettings;
using gibake::Scene;
using gibake::VoxelGrid;

const std::string kHouse = std::string(GIBAKE_SOURCE_DIR) + "/tests/volumes/house_on_ground.gltf";

Scene load(const std::string& path) {
  Scene s;
  EXPECT_TRUE(gibake::import_scene(path, gibake::ImportOptions{}, gibake::Context{}, s).is_ok()) << path;
  return s;
}

// The decision the bake takes with these grid settings (its budget split: half for the detail volume).
DetailDecision decide(const Scene& scene, const GridSettings& g = GridSettings{}) {
  gibake::SetupSettings setup;
  setup.enclosure_resolution = 128;  // as the bake's default
  tbb::task_arena arena(2);
  VoxelGrid v;
  EXPECT_TRUE(gibake::make_enclosure_voxels(scene, setup, gibake::Context{}, v, &arena).is_ok());
  DdgiVolumeDesc d{};
  EXPECT_TRUE(gibake::place_probe_grid(scene, g, d, &v).is_ok());
  return gibake::decide_detail_volume(v, scene.bounds, d, g, g.auto_max_probes / 2);
}

TEST(DetailVolume, AHouseOnALargeGroundGetsOneAroundTheHouse) {
  const DetailDecision d = decide(load(kHouse));
  EXPECT_TRUE(d.add) << d.text;
  ASSERT_TRUE(d.cluster.found);
  // The cluster holds the house (whole voxels of 160 / 128 = 1.25 m: at most one more a side).
  const float house_lo[3] = {-4.f, 0.f, -3.f}, house_hi[3] = {4.f, 3.2f, 3.f};
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(d.cluster.lo[a], house_lo[a] + 1e-4f) << a;
    EXPECT_GE(d.cluster.hi[a], house_hi[a] - 1e-4f) << a;
    EXPECT_GE(d.cluster.lo[a], house_lo[a] - 1.26f) << a;
    EXPECT_LE(d.cluster.hi[a], house_hi[a] + 1.26f) << a;
  }
  EXPECT_FLOAT_EQ(d.cluster.lo[1], 0.f);  // from the ground, not below it
  EXPECT_GE(d.spacing, 0.33f);  // the rule on the house: 8.75 m / 24 = 0.365 m
  EXPECT_LE(d.spacing, 0.44f);
  EXPECT_GE(d.default_spacing, 2.f * d.spacing);
  EXPECT_LT(d.fraction, 0.01f);
  EXPECT_LE(d.probes, GridSettings{}.auto_max_probes / 2);
  // The box is the cluster padded by one spacing on every side (the blend's fade band).
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(d.lo[a], d.cluster.lo[a] - d.spacing, 1e-4f) << a;
    EXPECT_NEAR(d.hi[a], d.cluster.hi[a] + d.spacing, 1e-4f) << a;
  }
}

TEST(DetailVolume, ASmallBudgetStillGetsOneWithinItsShare) {
  GridSettings g;
  g.auto_max_probes = 2000;
  const DetailDecision d = decide(load(kHouse), g);
  EXPECT_TRUE(d.add) << d.text;
  EXPECT_LE(d.probes, 1000u);
  EXPECT_GE(d.default_spacing, 2.f * d.spacing);
}

TEST(DetailVolume, ScenesOneGridServesGetNone) {
  std::vector<std::string> scenes = {std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf",
                                     std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/two_rooms.gltf"};
  const std::string nvpro = "/work/shared/assets/cornell-box-nvpro/cornellBox.gltf";
  if (std::filesystem::exists(nvpro)) scenes.push_back(nvpro);
  for (const std::string& path : scenes) {
    const DetailDecision d = decide(load(path));
    EXPECT_FALSE(d.add) << path << ": " << d.text;
  }
}

TEST(DetailVolume, ABareGroundHasNothingRaised) {
  Scene s;
  const int m = gibake::test::add_material(s, 0.5f);
  gibake::test::add_quad(s, {-80, 0, -80}, {80, 0, -80}, {80, 0, 80}, {-80, 0, 80}, {0, 1, 0}, m);
  const DetailDecision d = decide(s);
  EXPECT_FALSE(d.cluster.found);
  EXPECT_FALSE(d.add);
}

TEST(DetailVolume, BoxGridsKeepTheirSpacingAndCentreTheCells) {
  const GridSettings g = gibake::box_grid_settings(GridSettings{}, {0.f, 0.f, 0.f}, {2.f, 1.f, 0.3f}, 0.5f);
  ASSERT_TRUE(g.explicit_bounds);
  EXPECT_EQ(g.counts[0], 4);
  EXPECT_EQ(g.counts[1], 2);
  EXPECT_EQ(g.counts[2], 1);
  EXPECT_FLOAT_EQ(g.grid_min[0], 0.25f);  // cell centres
  EXPECT_FLOAT_EQ(g.grid_max[0], 1.75f);
  EXPECT_FLOAT_EQ(g.grid_min[2], 0.15f);
  Scene empty;
  DdgiVolumeDesc d{};
  ASSERT_TRUE(gibake::place_probe_grid(empty, g, d).is_ok());
  EXPECT_FLOAT_EQ(d.spacing[0], 0.5f);
  EXPECT_FLOAT_EQ(d.spacing[1], 0.5f);
  EXPECT_EQ(gibake::box_grid_probes({0.f, 0.f, 0.f}, {2.f, 1.f, 0.3f}, 0.5f), 8u);
}

}  // namespace
