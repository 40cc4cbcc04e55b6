// The volume plan (bake/ddgi/volume_plan.h) places every volume's grid once and the bake reads it.
// Known by construction: each planned grid is what place_probe_grid gives for the volume's final
// settings (the default grid fitted to the plan's voxels, a box grid as its box); on the house on a
// large ground (tests/volumes/make_house.py) the detail volume cuts the default grid's budget, so
// the default grid is coarser than the whole budget's grid the rule judged; a bake handed a placed
// grid bakes on that grid and places none.
#include <gtest/gtest.h>

#include <algorithm>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/probe_grid.h"
#include "bake/ddgi/volume_plan.h"
#include "bake/pipeline/devices.h"
#include "io/gltf/import.h"
#include "scene_builders.h"

namespace {

using gibake::GridSettings;
using gibake::PlacedGrid;
using gibake::Scene;
using gibake::VolumePlan;

Scene load(const std::string& relative) {
  Scene s;
  const std::string path = std::string(GIBAKE_SOURCE_DIR) + "/" + relative;
  EXPECT_TRUE(gibake::import_scene(path, gibake::ImportOptions{}, gibake::Context{}, s).is_ok()) << path;
  return s;
}

PlacedGrid place(const Scene& scene, const GridSettings& g, const gibake::VoxelGrid* voxels) {
  PlacedGrid p;
  EXPECT_TRUE(gibake::place_probe_grid(scene, g, voxels, p).is_ok());
  return p;
}

void expect_same_grid(const PlacedGrid& a, const PlacedGrid& b) {
  EXPECT_EQ(a.desc.counts, b.desc.counts);
  EXPECT_EQ(a.desc.grid_min, b.desc.grid_min);
  EXPECT_EQ(a.desc.grid_max, b.desc.grid_max);
  EXPECT_EQ(a.desc.spacing, b.desc.spacing);
  EXPECT_EQ(a.placement.fit.fitted, b.placement.fit.fitted);
  EXPECT_EQ(a.placement.unfitted_probes, b.placement.unfitted_probes);
  EXPECT_EQ(a.placement.outer_layer, b.placement.outer_layer);
}

// One grid serves a room open at the front: the default grid is the rule's whole-budget grid,
// fitted to the plan's voxels (the slabs dropped, a layer outside the open side: probe_fit_test.cpp).
TEST(VolumePlan, OneGridIsTheDefaultGridFittedToThePlansVoxels) {
  const Scene scene = gibake::test::open_front_room(0.7f);
  VolumePlan plan;
  ASSERT_TRUE(gibake::plan_ddgi_volumes(scene, gibake::DdgiSettings{}, gibake::VolumeSettings{}, gibake::Context{}, plan));
  ASSERT_EQ(plan.volumes.size(), 1u);
  ASSERT_FALSE(plan.voxels.empty());
  EXPECT_FALSE(plan.rule_text.empty());  // the rule ran and said why it added nothing
  const PlacedGrid expected = place(scene, GridSettings{}, &plan.voxels);
  EXPECT_TRUE(expected.placement.fit.fitted);
  EXPECT_TRUE(expected.placement.outer_layer[5]);
  expect_same_grid(plan.volumes[0].placed, expected);
  // With the rule off (inspect's plan) the one grid is placed on its own, fitted alike.
  gibake::VolumeSettings no_rule;
  no_rule.detail_volumes = false;
  VolumePlan alone;
  ASSERT_TRUE(gibake::plan_ddgi_volumes(scene, gibake::DdgiSettings{}, no_rule, gibake::Context{}, alone));
  ASSERT_EQ(alone.volumes.size(), 1u);
  EXPECT_TRUE(alone.rule_text.empty());
  expect_same_grid(alone.volumes[0].placed, expected);
}

// The house gets a detail volume; the default grid keeps the budget less its probes and is placed
// with that budget (coarser than the whole budget's grid), the detail volume as its box. Refined
// volumes (refine.h, outside the budget) come after them.
TEST(VolumePlan, ACutBudgetPlacesTheDefaultGridWithItsShare) {
  const Scene scene = load("tests/volumes/house_on_ground.gltf");
  VolumePlan plan;
  ASSERT_TRUE(gibake::plan_ddgi_volumes(scene, gibake::DdgiSettings{}, gibake::VolumeSettings{}, gibake::Context{}, plan));
  ASSERT_GE(plan.volumes.size(), 2u);
  for (size_t i = 2; i < plan.volumes.size(); ++i) EXPECT_EQ(plan.volumes[i].kind, gibake::VolumeKind::Refined);
  const gibake::PlannedVolume& def = plan.volumes[0];
  const gibake::PlannedVolume& detail = plan.volumes[1];
  EXPECT_EQ(detail.kind, gibake::VolumeKind::Detail);
  EXPECT_LT(def.grid.auto_max_probes, GridSettings{}.auto_max_probes);
  expect_same_grid(def.placed, place(scene, def.grid, &plan.voxels));
  expect_same_grid(detail.placed, place(scene, detail.grid, nullptr));
  const PlacedGrid whole = place(scene, GridSettings{}, &plan.voxels);
  EXPECT_GT(def.placed.desc.spacing[0], whole.desc.spacing[0]);
  EXPECT_LE(uint64_t(def.placed.desc.probe_count()), def.grid.auto_max_probes);
}

// Without the default grid nothing is fitted: no voxels, each given box as placed from its settings.
TEST(VolumePlan, GivenVolumesAloneNeedNoVoxels) {
  const Scene scene = load("samples/cornell/cornell.gltf");
  gibake::VolumeSettings volumes;
  volumes.default_volume = false;
  volumes.given.push_back({{-0.9f, 0.1f, -0.9f}, {0.9f, 1.9f, 0.9f}, 0.3f});
  volumes.given.push_back({{-0.5f, 0.2f, -0.5f}, {0.5f, 1.f, 0.5f}, 0.f});
  VolumePlan plan;
  ASSERT_TRUE(gibake::plan_ddgi_volumes(scene, gibake::DdgiSettings{}, volumes, gibake::Context{}, plan));
  ASSERT_EQ(plan.volumes.size(), 2u);
  EXPECT_TRUE(plan.voxels.empty());
  EXPECT_TRUE(plan.rule_text.empty());
  for (const gibake::PlannedVolume& v : plan.volumes) expect_same_grid(v.placed, place(scene, v.grid, nullptr));
  EXPECT_FLOAT_EQ(plan.volumes[0].placed.desc.spacing[0], 0.3f);
}

// Handed a placed grid, the bake bakes on it (not on the grid its settings would place) and builds
// no voxels to place one.
TEST(VolumePlan, TheBakeReadsTheHandedGrid) {
  const Scene scene = gibake::test::open_front_room(0.7f);
  gibake::DdgiSettings s;  // the default rule: a fitted grid, were the bake to place it
  s.rays = 8;
  s.relocate = false;
  s.cgal_check = false;
  s.bounces = 1;
  GridSettings given;
  given.explicit_bounds = true;
  given.grid_min = {0.2f, 0.2f, 0.2f};
  given.grid_max = {0.8f, 0.6f, 0.8f};
  given.counts = {2, 3, 2};
  const PlacedGrid handed = place(scene, given, nullptr);
  const gibake::PipelineDevices platform;
  gibake::RunContext run;
  run.platform = &platform;
  run.placed = &handed;
  gibake::DdgiResult result;
  gibake::DdgiReport report;
  ASSERT_TRUE(gibake::bake_ddgi(scene, s, run, gibake::Context{}, result, report));
  EXPECT_EQ(result.desc.counts, handed.desc.counts);
  EXPECT_EQ(result.desc.grid_min, handed.desc.grid_min);
  EXPECT_EQ(result.desc.grid_max, handed.desc.grid_max);
  EXPECT_FALSE(report.placement.fit.fitted);
  EXPECT_EQ(report.probes, 12);
  const auto& stages = report.stage_seconds;
  EXPECT_TRUE(std::none_of(stages.begin(), stages.end(), [](const auto& st) { return st.first == "voxelize (grid fit)"; }));
}

}  // namespace
