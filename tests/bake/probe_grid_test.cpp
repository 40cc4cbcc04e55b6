// The default spacing rule (bake/ddgi/probe_grid.h) on boxes whose answer is arithmetic: a building
// gets a probe a metre while the budget allows, a budget widens the spacing until the grid fits it,
// rooms keep longest / 24 (never below 0.25 m), small models keep 8 cells.
#include "bake/ddgi/probe_grid.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using gibake::DdgiVolumeDesc;
using gibake::GridSettings;

DdgiVolumeDesc grid_for(float x, float y, float z, GridSettings s = {}) {
  gibake::Scene scene;
  scene.bounds.extend({0.f, 0.f, 0.f});
  scene.bounds.extend({x, y, z});
  DdgiVolumeDesc d;
  EXPECT_TRUE(gibake::place_probe_grid(scene, s, d).is_ok());
  return d;
}

TEST(ProbeGridRule, BuildingsGetAProbeAMetreWithinTheBudget) {
  const DdgiVolumeDesc d = grid_for(48.f, 20.f, 30.f);  // 48 x 20 x 30 = 28,800 cells <= 32,768
  EXPECT_EQ(d.counts[0], 48);
  EXPECT_EQ(d.counts[1], 20);
  EXPECT_EQ(d.counts[2], 30);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(d.spacing[a], 1.f, 1e-5f);
}

TEST(ProbeGridRule, TheBudgetWidensTheSpacing) {
  GridSettings s;
  s.auto_max_probes = 4000;
  const DdgiVolumeDesc d = grid_for(48.f, 20.f, 30.f, s);
  EXPECT_LE(d.probe_count(), 4000);
  // Widened in 5% steps: the last step before it fit had more than the budget.
  const float wider = d.spacing[0];
  EXPECT_GT(wider, 1.f);
  const double before = std::ceil(48.0 / (wider / 1.05) - 1e-4) * std::ceil(20.0 / (wider / 1.05) - 1e-4) *
                        std::ceil(30.0 / (wider / 1.05) - 1e-4);
  EXPECT_GT(before, 4000.0);
}

TEST(ProbeGridRule, RoomsAndSmallModels) {
  DdgiVolumeDesc d = grid_for(12.f, 3.f, 6.f);  // 12 / 24 = 0.5 m
  EXPECT_EQ(d.counts[0], 24);
  EXPECT_NEAR(d.spacing[0], 0.5f, 1e-5f);
  d = grid_for(4.8f, 3.f, 4.f);  // 4.8 / 24 = 0.2 m, raised to the 0.25 m floor: 0.25 m, 20 cells
  EXPECT_EQ(d.counts[0], 20);
  EXPECT_NEAR(d.spacing[0], 0.25f, 1e-5f);
  d = grid_for(2.f, 2.f, 2.f);  // 2 / 24 = 0.083 m, raised to the 0.25 m floor: 8 cells
  EXPECT_EQ(d.counts[0], 8);
  d = grid_for(0.07f, 0.03f, 0.05f);  // a 7 cm model: 8 cells along its longest side
  EXPECT_EQ(d.counts[0], 8);
  EXPECT_NEAR(d.spacing[0], 0.07f / 8.f, 1e-6f);
}

// --probe-counts several probes deep along an axis where the box has no depth (a floor alone)
// would put them on one spot: refused as an argument error naming the axis, before any bake.
TEST(ProbeGridRule, CountsAcrossAFlatBoxAreRefused) {
  gibake::Scene scene;
  scene.bounds.extend({-5.f, 0.f, -5.f});
  scene.bounds.extend({5.f, 0.f, 5.f});
  GridSettings s;
  s.counts = {4, 4, 4};
  DdgiVolumeDesc d;
  const gibake::Status st = gibake::place_probe_grid(scene, s, d);
  ASSERT_FALSE(st.is_ok());
  EXPECT_EQ(st.code(), gibake::ExitCode::BadArguments);
  EXPECT_NE(st.message().find("4 probes along y"), std::string::npos) << st.message();
  s.counts = {4, 1, 4};
  EXPECT_TRUE(gibake::place_probe_grid(scene, s, d).is_ok());
  EXPECT_EQ(d.spacing[1], 0.f);
  s.counts = {4, 4, 4};
  s.padding = 1.f;
  EXPECT_TRUE(gibake::place_probe_grid(scene, s, d).is_ok());
  EXPECT_GT(d.spacing[1], 0.f);
}

}  // namespace
