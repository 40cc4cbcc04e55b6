// Refinement by the bake's check (bake/ddgi/refine.h decide_check_refinement, and
// bake/pipeline/check_refine.h check_misses). Known by construction: misses placed at chosen
// points of a grid whose bricks are known, and patches whose ratios and reference noise are given,
// so which bricks are refined, in which order, and which patches count as missed follow from the
// rules alone. The end-to-end effect on a picture against the path-traced truth is
// tests/preview/picture_cli_test.cpp (PictureRefinement).
#include "bake/pipeline/check_refine.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "bake/ddgi/probe_grid.h"
#include "bake/ddgi/refine.h"

namespace {

using gibake::CheckMiss;
using gibake::RefineDecision;
using gibake::RefineSettings;

// A 12 x 4 x 12 m cell box of 1 m cells from the origin: bricks of 2 cells are 2 m cubes.
gibake::DdgiVolumeDesc coarse_grid() {
  gibake::DdgiVolumeDesc d;
  d.counts = {12, 4, 12};
  d.spacing = {1.f, 1.f, 1.f};
  d.grid_min = {0.5f, 0.5f, 0.5f};
  d.grid_max = {11.5f, 3.5f, 11.5f};
  return d;
}

void add_misses(std::vector<CheckMiss>& out, float x, float y, float z, int points, float error) {
  for (int i = 0; i < points; ++i) out.push_back(CheckMiss{{x + 0.01f * float(i), y, z}, error});
}

bool inside(const gibake::RefinedBox& b, float x, float y, float z) {
  return x >= b.lo[0] && x <= b.hi[0] && y >= b.lo[1] && y <= b.hi[1] && z >= b.lo[2] && z <= b.hi[2];
}
bool any_inside(const RefineDecision& d, float x, float y, float z) {
  return std::any_of(d.boxes.begin(), d.boxes.end(), [&](const gibake::RefinedBox& b) { return inside(b, x, y, z); });
}

// Two missed places: brick (0,0,0) with 4 points off by 30%, brick (4,0,4) with 8 points off by 20%.
std::vector<CheckMiss> two_places() {
  std::vector<CheckMiss> m;
  add_misses(m, 1.2f, 0.3f, 1.5f, 4, 0.3f);
  add_misses(m, 9.5f, 0.2f, 9.5f, 8, 0.2f);
  return m;
}

TEST(CheckRefinement, RefinesTheBricksHoldingTheMissesAtHalfTheSpacing) {
  RefineDecision d;
  gibake::decide_check_refinement(coarse_grid(), {}, two_places(), 1 << 20, RefineSettings{}, d);
  ASSERT_EQ(d.boxes.size(), 2u) << d.text;
  EXPECT_FLOAT_EQ(d.spacing, 0.5f);
  EXPECT_EQ(d.chosen, 2u);
  EXPECT_TRUE(any_inside(d, 1.2f, 0.3f, 1.5f));
  EXPECT_TRUE(any_inside(d, 9.5f, 0.2f, 9.5f));
  EXPECT_FALSE(any_inside(d, 5.f, 0.5f, 5.f));   // between them: nothing missed there
  EXPECT_FALSE(any_inside(d, 1.2f, 3.f, 1.5f));  // above the first: another brick
  uint64_t probes = 0;
  for (const gibake::RefinedBox& b : d.boxes) {
    for (int a = 0; a < 3; ++a) EXPECT_FLOAT_EQ(b.hi[a] - b.lo[a], 2.f);  // one brick each
    probes += gibake::box_grid_probes(b.lo, b.hi, d.spacing);
  }
  EXPECT_EQ(d.probes, probes);
  EXPECT_EQ(probes, 2u * 64u);  // 4 probes a side in a 2 m brick at 0.5 m
  EXPECT_NE(d.text.find("refinement by check: 2 volumes"), std::string::npos) << d.text;
}

TEST(CheckRefinement, TheLargestSummedErrorFirstWithinTheBudget) {
  RefineDecision d;  // room for one brick: the 8 points off by 20% (1.6) before the 4 off by 30% (1.2)
  gibake::decide_check_refinement(coarse_grid(), {}, two_places(), 64, RefineSettings{}, d);
  ASSERT_EQ(d.boxes.size(), 1u) << d.text;
  EXPECT_TRUE(any_inside(d, 9.5f, 0.2f, 9.5f));
  EXPECT_FALSE(any_inside(d, 1.2f, 0.3f, 1.5f));
  EXPECT_EQ(d.candidates, 2u);
  EXPECT_LE(d.probes, 64u);
}

TEST(CheckRefinement, LeavesBricksAlreadyFineAndRefusesBoxesOfAir) {
  // A volume at 0.5 m over the first brick: only the second is refined.
  gibake::FinerVolume fine{{0.f, 0.f, 0.f}, {2.f, 2.f, 2.f}, 0.5f};
  RefineDecision d;
  gibake::decide_check_refinement(coarse_grid(), {fine}, two_places(), 1 << 20, RefineSettings{}, d);
  ASSERT_EQ(d.boxes.size(), 1u) << d.text;
  EXPECT_TRUE(any_inside(d, 9.5f, 0.2f, 9.5f));
  // A miss in each corner brick of the ground layer, at most 3 volumes: the corners are apart
  // even on tiles of 2 bricks, so one is left out rather than boxed with the air between them.
  std::vector<CheckMiss> corners;
  for (float x : {1.f, 11.f})
    for (float z : {1.f, 11.f}) add_misses(corners, x, 0.5f, z, 1, 0.1f + 0.01f * (x + z));
  RefineSettings few;
  few.max_volumes = 3;
  gibake::decide_check_refinement(coarse_grid(), {}, corners, 1 << 20, few, d);
  EXPECT_EQ(d.boxes.size(), 3u) << d.text;
  EXPECT_EQ(d.chosen, 3u);
  EXPECT_FALSE(any_inside(d, 1.f, 0.5f, 1.f));  // the least error
  for (const gibake::RefinedBox& b : d.boxes)
    for (int a = 0; a < 3; ++a) EXPECT_LE(b.hi[a] - b.lo[a], 4.f + 1e-4f);  // a tile of 2 bricks at most
}

TEST(CheckRefinement, NoneWithoutMissesOrBudget) {
  RefineDecision d;
  gibake::decide_check_refinement(coarse_grid(), {}, two_places(), 0, RefineSettings{}, d);
  EXPECT_TRUE(d.boxes.empty());
  gibake::decide_check_refinement(coarse_grid(), {}, {}, 1 << 20, RefineSettings{}, d);
  EXPECT_TRUE(d.boxes.empty());
  EXPECT_NE(d.text.find("refinement by check: none"), std::string::npos) << d.text;
}

// A patch of `points` points at x, with summed reference and baked luminance and the reference's
// standard error, as the check leaves them.
void add_patch(gibake::ReconstructionReference& ref, gibake::ReconstructionError& err, float x, uint32_t points,
               float reference, float baked, float stderr_) {
  gibake::ReconstructionPatch p;
  p.points = points;
  p.reference = reference;
  p.baked = baked;
  p.reference_stderr = stderr_;
  ref.patches.push_back(p);
  ref.rays.push_back(0);
  ref.points.emplace_back();
  for (uint32_t i = 0; i < points; ++i) {
    gibake::ReconstructionReference::Point pt{};
    pt.p = {x, float(i), 0.f};
    ref.points.back().push_back(pt);
  }
  if (points > 0) err.samples.push_back(p);  // the check keeps the patches that met a surface
}

TEST(CheckRefinement, APatchMissesWhenOffBeyondTheToleranceAndItsOwnNoise) {
  gibake::ReconstructionReference ref;
  gibake::ReconstructionError err;
  add_patch(ref, err, 0.f, 16, 16.f, 20.f, 0.5f);   // 25% off, 3% noise: missed
  add_patch(ref, err, 1.f, 0, 0.f, 0.f, 0.f);       // met no surface
  add_patch(ref, err, 2.f, 16, 16.f, 20.f, 4.f);    // 25% off, but 25% noise: not
  add_patch(ref, err, 3.f, 16, 16.f, 16.8f, 0.1f);  // 5% off: not
  add_patch(ref, err, 4.f, 4, 4.f, 3.f, 0.1f);      // 25% low, 4 points: missed
  add_patch(ref, err, 5.f, 16, 1e-6f, 2e-6f, 0.f);  // under the floor: left out
  gibake::ReconstructionSettings s;
  const std::vector<CheckMiss> m = gibake::check_misses(ref, err, s);
  ASSERT_EQ(m.size(), 20u);
  for (size_t i = 0; i < 16; ++i) {
    EXPECT_FLOAT_EQ(m[i].p[0], 0.f);
    EXPECT_FLOAT_EQ(m[i].error, 0.25f);
  }
  for (size_t i = 16; i < 20; ++i) {
    EXPECT_FLOAT_EQ(m[i].p[0], 4.f);
    EXPECT_FLOAT_EQ(m[i].error, 0.25f);
  }
}

}  // namespace
