// The default grid fitted to the enclosure voxels (bake/ddgi/probe_fit.h) on scenes whose answer is
// known by construction: a court on a solid slab (no probe below its floor or inside the slab, the
// box and counts derived by hand below), a court between solid wings (none inside the wings), a
// small closed model and a sphere (nothing to drop: the box stays), explicit settings (unchanged),
// the same placement for any thread count, and the bake itself (the summary's figures).
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/ddgi/probe_fit.h"
#include "bake/ddgi/probe_grid.h"
#include "bake/voxel/enclosure.h"
#include "scene_builders.h"

namespace {

using gibake::DdgiVolumeDesc;
using gibake::GridPlacement;
using gibake::GridSettings;
using gibake::Scene;
using gibake::SlabReason;
using gibake::VoxelGrid;

VoxelGrid enclosure_voxels(const Scene& scene, int threads = 2) {
  gibake::SetupSettings setup;
  setup.enclosure_resolution = 128;  // as the bake's default
  gibake::Context ctx;
  tbb::task_arena arena(threads);
  VoxelGrid v;
  EXPECT_TRUE(gibake::make_enclosure_voxels(scene, setup, ctx, v, &arena).is_ok());
  return v;
}

DdgiVolumeDesc place(const Scene& scene, const GridSettings& g, const VoxelGrid* v, GridPlacement* p = nullptr) {
  DdgiVolumeDesc d{};
  EXPECT_TRUE(gibake::place_probe_grid(scene, g, d, v, p).is_ok());
  return d;
}

// A 16 x 16 m court: a solid slab 4 m thick (y -4..0, normals out: closed space inside) and four
// walls 4 m high on its edges, open to the sky.
// These scenes' figures are worked out at longest side / 16 (a 16 m box: 1 m cells); what is tested
// is the fit, not the rule's divisor (the CLI's default, 24: tests/bake/probe_grid_test.cpp).
GridSettings rule16() {
  GridSettings g;
  g.auto_cells = 16;
  return g;
}

Scene court_on_slab() {
  Scene s;
  const int m = gibake::test::add_material(s, 0.5f);
  gibake::test::add_box(s, {0, -4, 0}, {16, 0, 16}, false, m);
  gibake::test::add_box(s, {0, 0, 0}, {16, 4, 16}, true, m, (1u << 2) | (1u << 3));  // no floor, no roof
  return s;
}

// The voxels are 16 / 128 = 0.125 m, the grid centred on the scene box (dims ceil(extent / 0.125)
// + 3): voxel i along x covers [-0.1875 + 0.125 i, ...), along y [-4.1875 + 0.125 j, ...). The walls
// at x = 0 and 16 fill voxels 1 and 129, the floor at y = 0 voxel 33, so the useful space (open,
// above the floor, between the walls) is voxels 2..128 along x and z and 34..65 along y (65: the
// walls' top edge at y = 4, the box's top). Grown by one voxel to hold the surfaces that bound it:
// y in [-0.0625, 4] (the floor's voxel 33 in). Along x and z the box would lose nothing beyond the
// walls it ends at: x, z stay [0, 16].
TEST(ProbeFit, ACourtOnASlabKeepsNoProbeBelowItsFloor) {
  const Scene scene = court_on_slab();
  const VoxelGrid v = enclosure_voxels(scene);
  GridPlacement p;
  const DdgiVolumeDesc d = place(scene, rule16(), &v, &p);
  ASSERT_TRUE(p.fit.fitted);
  EXPECT_TRUE(p.fit.enclosed);
  EXPECT_EQ(p.fit.lo[0], 0.f);
  EXPECT_EQ(p.fit.hi[0], 16.f);
  EXPECT_NEAR(p.fit.lo[1], -0.0625f, 1e-4f);
  EXPECT_EQ(p.fit.hi[1], 4.f);
  EXPECT_EQ(p.fit.lo[2], 0.f);
  for (int side : {0, 1, 3, 4, 5}) EXPECT_EQ(p.fit.dropped[side], 0.f) << side;
  EXPECT_NEAR(p.fit.dropped[2], 3.9375f, 1e-4f);  // the slab, below the court's floor
  EXPECT_EQ(p.fit.why[2], SlabReason::Solid);
  // Without the fit: 16 x 8 x 16 m at longest / 16 = 1 m: 16 x 8 x 16 = 2048 probes.
  EXPECT_EQ(p.unfitted_probes, 2048u);
  EXPECT_NEAR(p.unfitted_spacing, 1.f, 1e-6f);
  // On the fitted box (16 x 4.0625 x 16): longest / 16 = 1 m, so 16 x 4 x 16 = 1024 probes (the
  // probes saved are not spent on a finer grid), the 4 layers centred on the box: y from 0.46875;
  // then one layer above the walls' tops at 4.46875 (the open top: open sky beside the walls'
  // edges, probe_fit.h): 16 x 5 x 16.
  EXPECT_EQ(d.counts[0], 16);
  EXPECT_EQ(d.counts[1], 5);
  EXPECT_TRUE(p.outer_layer[3]);
  for (int side : {0, 1, 2, 4, 5}) EXPECT_FALSE(p.outer_layer[side]) << side;
  EXPECT_EQ(d.counts[2], 16);
  EXPECT_NEAR(d.spacing[1], 1.f, 1e-5f);
  EXPECT_NEAR(d.grid_min[1], 0.46875f, 1e-4f);
  // The floor lies in the grid's cell box (half a spacing below its lowest layer), where the
  // sampler reads it from the probes placed for it rather than clamped from a layer further up.
  EXPECT_LE(d.grid_min[1] - 0.5f * d.spacing[1], 0.f);
  // No probe below the floor (y = 0) or in the walls; the lowest layer is 0.47 m above the floor.
  for (int32_t i = 0; i < d.probe_count(); ++i) {
    const auto q = gibake::probe_rest_position(d, i);
    ASSERT_GT(q[1], 0.3f) << i;
    ASSERT_LT(q[1], 4.6f) << i;
    for (int a : {0, 2}) ASSERT_TRUE(q[a] > 0.f && q[a] < 16.f) << i;  // none in the walls
  }
  // Unfitted, the bottom half of the grid (4 of 8 layers) lay inside the slab.
  const DdgiVolumeDesc before = place(scene, rule16(), nullptr);
  EXPECT_NEAR(before.grid_min[1], -3.5f, 1e-4f);
}

// A court 8 x 8 m between solid wings 3 m high on a solid slab, in a 16 x 16 m footprint: open
// space above the wings is outside the enclosure (the court is 256 of the 448 m^3 of open space,
// over half), so the box keeps the court alone.
TEST(ProbeFit, ACourtBetweenSolidWingsKeepsTheCourt) {
  Scene s;
  const int m = gibake::test::add_material(s, 0.5f);
  gibake::test::add_box(s, {0, -1, 0}, {16, 0, 16}, false, m);
  gibake::test::add_box(s, {0, 0, 0}, {4, 3, 16}, false, m);    // -x wing
  gibake::test::add_box(s, {12, 0, 0}, {16, 3, 16}, false, m);  // +x wing
  gibake::test::add_box(s, {4, 0, 0}, {12, 3, 4}, false, m);    // -z wing
  gibake::test::add_box(s, {4, 0, 12}, {12, 3, 16}, false, m);  // +z wing
  gibake::test::add_box(s, {4, 3, 4}, {12, 4, 12}, true, m, (1u << 2) | (1u << 3));  // parapet above
  const VoxelGrid v = enclosure_voxels(s);
  GridPlacement p;
  const DdgiVolumeDesc d = place(s, rule16(), &v, &p);
  ASSERT_TRUE(p.fit.fitted);
  EXPECT_TRUE(p.fit.enclosed);
  for (int a : {0, 2}) {
    EXPECT_NEAR(p.fit.lo[a], 4.f, 0.13f);
    EXPECT_NEAR(p.fit.hi[a], 12.f, 0.13f);
    EXPECT_EQ(p.fit.why[2 * a], SlabReason::Solid);
  }
  EXPECT_NEAR(p.fit.lo[1], 0.f, 0.13f);
  EXPECT_GT(p.fit.outside, 0u);
  for (int32_t i = 0; i < d.probe_count(); ++i) {
    const auto q = gibake::probe_rest_position(d, i);
    ASSERT_TRUE(q[0] > 4.f && q[0] < 12.f && q[2] > 4.f && q[2] < 12.f && q[1] > 0.f) << i;
  }
  // The rule on the court's box alone (longest / 16, about 0.5 m), finer than on the whole (1 m).
  EXPECT_NEAR(d.spacing[0], (p.fit.hi[0] - p.fit.lo[0]) / 16.f, 1e-4f);
  EXPECT_NEAR(p.unfitted_spacing, 1.f, 1e-6f);
}

// A 7 cm closed cube and a sphere: no open space inside their boxes but corners, nothing to drop.
TEST(ProbeFit, SmallModelsKeepTheirGrid) {
  Scene cube;
  gibake::test::add_box(cube, {0, 0, 0}, {0.07f, 0.07f, 0.07f}, false, gibake::test::add_material(cube, 0.5f));
  const VoxelGrid vc = enclosure_voxels(cube);
  GridPlacement p;
  const DdgiVolumeDesc d = place(cube, rule16(), &vc, &p);
  EXPECT_FALSE(p.fit.fitted);
  EXPECT_EQ(p.fit.useful, 0u);
  const DdgiVolumeDesc plain = place(cube, rule16(), nullptr);
  EXPECT_EQ(d.counts, plain.counts);
  EXPECT_EQ(d.grid_min, plain.grid_min);
  EXPECT_EQ(d.counts[0], 8);  // auto_min_cells along its longest side

  Scene ball;
  gibake::test::add_sphere(ball, {0, 0, 0}, 1.f, 32, 16, gibake::test::add_material(ball, 0.5f));
  const VoxelGrid vb = enclosure_voxels(ball);
  GridPlacement pb;
  place(ball, rule16(), &vb, &pb);
  EXPECT_FALSE(pb.fit.fitted);
  EXPECT_GT(pb.fit.below_floor, 0u);  // under the sphere, but its box's corners reach the bottom
}

TEST(ProbeFit, ExplicitSettingsKeepTheirMeaning) {
  const Scene scene = court_on_slab();
  const VoxelGrid v = enclosure_voxels(scene);
  GridSettings spacing;
  spacing.spacing = 0.5f;
  GridSettings counts;
  counts.counts = {4, 5, 6};
  GridSettings bounds = counts;
  bounds.explicit_bounds = true;
  bounds.grid_min = {-1, -2, -3};
  bounds.grid_max = {1, 2, 3};
  GridSettings off;
  off.fit_to_voxels = false;
  for (const GridSettings& g : {spacing, counts, bounds, off}) {
    GridPlacement p;
    const DdgiVolumeDesc with = place(scene, g, &v, &p);
    const DdgiVolumeDesc without = place(scene, g, nullptr);
    EXPECT_FALSE(p.fit.fitted);
    EXPECT_EQ(with.counts, without.counts);
    EXPECT_EQ(with.grid_min, without.grid_min);
    EXPECT_EQ(with.grid_max, without.grid_max);
  }
}

// --grid-padding pads the fitted box as it padded the whole one.
TEST(ProbeFit, PaddingPadsTheFittedBox) {
  const Scene scene = court_on_slab();
  const VoxelGrid v = enclosure_voxels(scene);
  GridSettings padded = rule16();
  padded.padding = 0.5f;
  GridPlacement p;
  const DdgiVolumeDesc d = place(scene, padded, &v, &p);
  ASSERT_TRUE(p.fit.fitted);
  EXPECT_NEAR(p.fit.lo[1], -0.0625f, 1e-4f);  // the fit itself as without padding
  EXPECT_NEAR(p.fit.dropped[2], 3.9375f, 1e-4f);
  // The box is 17 x 5.0625 x 17 m (1 m cells: 17 x 5 x 17), its probes centred on it: the lowest
  // layer at 1.96875 - 2 = -0.03125, below the floor (only the padding puts it there) by less than
  // the padding; along x from 8 - 8 = 0, within 0.5 m outside the fitted walls. The
  // padding, not a layer outside the open top, says how far the grid reaches past the box.
  EXPECT_EQ(d.counts[1], 5);
  for (int side = 0; side < 6; ++side) EXPECT_FALSE(p.outer_layer[side]) << side;
  EXPECT_NEAR(d.grid_min[1], -0.03125f, 1e-4f);
  EXPECT_LE(d.grid_min[0], 0.f);
  EXPECT_GT(d.grid_min[0], -0.5f);
}

TEST(ProbeFit, TheSamePlacementForAnyThreadCount) {
  const Scene scene = court_on_slab();
  const VoxelGrid v1 = enclosure_voxels(scene, 1), v4 = enclosure_voxels(scene, 4);
  const DdgiVolumeDesc a = place(scene, rule16(), &v1), b = place(scene, rule16(), &v4);
  EXPECT_EQ(a.counts, b.counts);
  EXPECT_EQ(a.grid_min, b.grid_min);
  EXPECT_EQ(a.grid_max, b.grid_max);
}

// The bake places the fitted grid (it voxelizes before placing) and reports the fit.
TEST(ProbeFit, TheBakeUsesTheFittedGrid) {
  const Scene scene = court_on_slab();
  gibake::DdgiSettings s;
  s.grid = rule16();
  s.rays = 16;
  s.relocate = false;
  s.cgal_check = false;
  s.bounces = 1;
  gibake::SunLight sun;
  sun.direction = {0.3f, -1.f, 0.2f};
  sun.lux = 1000.f;
  s.suns.push_back(sun);
  gibake::Context ctx;
  gibake::DdgiResult result;
  gibake::DdgiReport report;
  ASSERT_TRUE(gibake::bake_ddgi(scene, s, ctx, result, report).is_ok());
  EXPECT_TRUE(report.placement.fit.fitted);
  EXPECT_EQ(result.desc.counts[1], 5);  // 4 in the court, 1 above its walls (the open top)
  EXPECT_GT(result.desc.grid_min[1], 0.3f);
  EXPECT_EQ(report.inactive, 0);  // no probe in the slab or the walls
  const std::string text = gibake::placement_text(report.placement);
  EXPECT_NE(text.find("-y 3.94 m: inside geometry or closed space"), std::string::npos) << text;
  EXPECT_NE(text.find("instead of 2048 probes 1 m apart"), std::string::npos) << text;
}

// A voxel grid in the run context (--voxels, --lpv, --vxgi at another --voxel-res) does not move
// the DDGI grid: the fit always reads voxels at the enclosure test's resolution.
TEST(ProbeFit, TheGridDoesNotDependOnTheRunsOtherVoxels) {
  const Scene scene = court_on_slab();
  gibake::DdgiSettings s;
  s.rays = 8;
  s.relocate = false;
  s.cgal_check = false;
  s.bounces = 1;
  gibake::Context ctx;
  gibake::DdgiResult alone, beside;
  gibake::DdgiReport report;
  ASSERT_TRUE(gibake::bake_ddgi(scene, s, ctx, alone, report).is_ok());
  gibake::SetupSettings coarse;
  coarse.enclosure_resolution = 40;
  VoxelGrid other;
  ASSERT_TRUE(gibake::make_enclosure_voxels(scene, coarse, ctx, other).is_ok());
  const gibake::PipelineDevices platform;
  gibake::RunContext run;
  run.platform = &platform;
  run.voxels = &other;
  ASSERT_TRUE(gibake::bake_ddgi(scene, s, run, ctx, beside, report).is_ok());
  EXPECT_EQ(alone.desc.counts, beside.desc.counts);
  EXPECT_EQ(alone.desc.grid_min, beside.desc.grid_min);
  EXPECT_EQ(alone.desc.grid_max, beside.desc.grid_max);
}

}  // namespace

// The open front is the one open side: one layer of probes outside it, a spacing beyond the
// lattice's outermost (which stays half a cell inside the box on every other side).
TEST(ProbeFit, AnOpenSideGetsOneLayerOfProbesOutside) {
  const Scene scene = gibake::test::open_front_room(0.7f);
  const VoxelGrid v = enclosure_voxels(scene);
  GridPlacement p;
  const DdgiVolumeDesc d = place(scene, GridSettings{}, &v, &p);
  for (int side = 0; side < 5; ++side) {
    EXPECT_FALSE(p.fit.open[side]) << side;
    EXPECT_FALSE(p.outer_layer[side]) << side;
  }
  EXPECT_TRUE(p.fit.open[5]);
  ASSERT_TRUE(p.outer_layer[5]);
  // The fit drops the 0.1 m slabs (three 0.033 m voxels, more than the 1.5 a side keeps) but not
  // the open front: the room, 4 m a side to within a voxel and grown by one to hold the walls, at
  // the rule's 0.25 m floor: 16 cells an axis (the fitted rule: floor(4.04 / 0.25 - 0.5) + 1),
  // probes 0.125 m from the inner faces; then the layer: 17 along z, the last 0.13 m in front of
  // the opening.
  ASSERT_TRUE(p.fit.fitted);
  EXPECT_EQ(d.counts[0], 16);
  EXPECT_EQ(d.counts[1], 16);
  EXPECT_EQ(d.counts[2], 17);
  EXPECT_FLOAT_EQ(d.spacing[2], 0.25f);
  EXPECT_NEAR(d.grid_min[0], 0.125f, 0.02f);
  EXPECT_NEAR(d.grid_max[0], 3.875f, 0.02f);
  EXPECT_NEAR(d.grid_min[2], 0.125f, 0.02f);  // the back: half a cell inside
  EXPECT_NEAR(d.grid_max[2], 4.125f, 0.02f);  // outside the open front
  EXPECT_NEAR(d.grid_max[2] - d.grid_min[2], 16 * 0.25f, 1e-4f);
  EXPECT_NE(gibake::placement_text(p).find("one layer of probes outside the open side +z"), std::string::npos);
  // A closed room (every side walled) and the same room without its voxels get no layer.
  Scene closed = gibake::test::open_front_room(0.7f);
  gibake::test::add_box(closed, {-0.1f, -0.1f, 4.f}, {4.1f, 4.1f, 4.1f}, false, 0);
  const VoxelGrid cv = enclosure_voxels(closed);
  GridPlacement cp;
  place(closed, GridSettings{}, &cv, &cp);
  for (int side = 0; side < 6; ++side) EXPECT_FALSE(cp.outer_layer[side]) << side;
  GridPlacement np;
  place(scene, GridSettings{}, nullptr, &np);
  for (int side = 0; side < 6; ++side) EXPECT_FALSE(np.outer_layer[side]) << side;
  // Within the budget only: one probe short of the layer's, the grid keeps its 16 cells.
  GridSettings tight;
  tight.auto_max_probes = uint64_t(16) * 16 * 17 - 1;
  GridPlacement tp;
  const DdgiVolumeDesc td = place(scene, tight, &v, &tp);
  EXPECT_EQ(td.counts[2], 16);
  EXPECT_FALSE(tp.outer_layer[5]);
}
