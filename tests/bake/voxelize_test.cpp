// Voxelize stage: occupancy (conservative overlap), zero-area triangles, thin walls, the exterior
// flood fill, determinism across thread counts, memory refusal. Answers come from an independent
// exact triangle/box test (voxel_test_util.h) and from scene geometry.
#include "bake/voxel/voxelize.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <set>

#include "bake/voxel/voxel_internal.h"
#include "bake/voxel/voxel_raster.h"
#include "tests/bake/scene_builders.h"
#include "tests/bake/voxel_test_util.h"

namespace gibake {
namespace {

using test::D3;

VoxelSettings occupancy_only(int32_t res) {
  VoxelSettings s;
  s.resolution = res;
  s.channels = false;
  s.sdf = false;
  return s;
}

// Every voxel the exact test says the triangle crosses (by more than 1e-6 voxel) is ours, and
// every voxel of ours meets the triangle grown by 1e-6 voxel.
void expect_exact_overlap(const D3 v[3], const std::set<int64_t>& ours, const std::array<int32_t, 3>& dims) {
  auto lin = [&](int x, int y, int z) { return int64_t(x) + int64_t(dims[0]) * (int64_t(y) + int64_t(dims[1]) * z); };
  for (int z = 0; z < dims[2]; ++z)
    for (int y = 0; y < dims[1]; ++y)
      for (int x = 0; x < dims[0]; ++x) {
        const D3 lo{double(x), double(y), double(z)}, hi{x + 1.0, y + 1.0, z + 1.0};
        const bool mine = ours.count(lin(x, y, z)) > 0;
        if (mine) {
          EXPECT_TRUE(test::triangle_meets_box(v[0], v[1], v[2], lo, hi, 1e-6))
              << "extra voxel " << x << "," << y << "," << z;
        } else {
          EXPECT_FALSE(test::triangle_meets_box(v[0], v[1], v[2], lo, hi, -1e-6))
              << "missed voxel " << x << "," << y << "," << z;
        }
      }
}

TEST(Voxelize, OneTriangleMatchesExactOverlap) {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  test::add_triangle(s, {0.1f, 0.2f, 0.3f}, {3.7f, 0.9f, 1.1f}, {1.3f, 2.9f, 3.4f}, {0, 0, 1}, m);
  VoxelGrid g;
  VoxelReport rep;
  ASSERT_TRUE(voxelize(s, occupancy_only(16), Context{}, g, &rep).is_ok());
  EXPECT_EQ(g.dims[0], 16 + 3);  // ceil(16) + 2 padding + 1
  std::set<int64_t> ours;
  for (const SurfaceVoxel& sv : g.surface) {
    ours.insert(g.linear(sv.ijk[0], sv.ijk[1], sv.ijk[2]));
    EXPECT_EQ(sv.fragments, 1u);
    EXPECT_EQ(g.find_surface(sv.ijk[0], sv.ijk[1], sv.ijk[2]), &sv);
    const auto c = g.voxel_center(sv.ijk[0], sv.ijk[1], sv.ijk[2]);
    EXPECT_EQ(g.space_at(c.data()), VoxelSpace::Surface);
  }
  EXPECT_EQ(g.find_surface(0, 0, 0), nullptr);
  EXPECT_EQ(g.find_surface(-1, 2, 2), nullptr);
  EXPECT_EQ(ours.size(), rep.surface_voxels);
  EXPECT_EQ(test::count_space(g, VoxelSpace::Surface), ours.size());
  EXPECT_EQ(test::count_space(g, VoxelSpace::Interior), 0u);  // one triangle encloses nothing
  for (size_t i = 1; i < g.surface.size(); ++i) {
    const auto& a = g.surface[i - 1].ijk;
    const auto& b = g.surface[i].ijk;
    EXPECT_LT(g.linear(a[0], a[1], a[2]), g.linear(b[0], b[1], b[2]));
  }
  D3 v[3];
  test::scene_triangle_voxels(s, g, 0, v);
  expect_exact_overlap(v, ours, g.dims);
  // The padding: no surface voxel on the grid's border.
  for (const SurfaceVoxel& sv : g.surface)
    for (int a = 0; a < 3; ++a) {
      EXPECT_GT(sv.ijk[a], 0);
      EXPECT_LT(sv.ijk[a], g.dims[a] - 1);
    }
}

// The rasterizer alone against the exact test on random triangles: large, small, slivers,
// axis-aligned ones on voxel boundaries.
TEST(Voxelize, RasterMatchesExactOverlapOnRandomTriangles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(0.5, 11.5), small(-0.6, 0.6);
  const std::array<int32_t, 3> dims{12, 12, 12};
  const int32_t d[3] = {12, 12, 12};
  for (int i = 0; i < 300; ++i) {
    D3 v[3];
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) v[k][a] = pos(rng);
    if (i % 3 == 1)  // small triangles around the first vertex
      for (int k = 1; k < 3; ++k)
        for (int a = 0; a < 3; ++a) v[k][a] = std::min(11.5, std::max(0.5, v[0][a] + small(rng)));
    if (i % 3 == 2)  // slivers: the third point near the first edge's midpoint
      for (int a = 0; a < 3; ++a) v[2][a] = 0.5 * (v[0][a] + v[1][a]) + 1e-3 * small(rng);
    if (i % 10 == 0)  // exactly on a voxel boundary plane
      for (int k = 0; k < 3; ++k) v[k][1] = 6.0;
    const voxel::TriangleRaster tr = voxel::setup_triangle(v[0].data(), v[1].data(), v[2].data(), d);
    std::set<int64_t> ours;
    size_t calls = 0;
    voxel::rasterize_triangle(tr, [&](int32_t x, int32_t y, int32_t z) {
      ours.insert(int64_t(x) + 12 * (int64_t(y) + 12 * z));
      ++calls;
    });
    EXPECT_EQ(calls, ours.size()) << "a voxel reported twice, triangle " << i;
    expect_exact_overlap(v, ours, dims);
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << "triangle " << i;
      break;
    }
  }
}

// The one-voxel shortcut (voxel::single_voxel) against the full rasterizer: when it answers, the
// rasterizer reports exactly that voxel and the same degeneracy; tiny, sliver, point and
// boundary-touching triangles included.
TEST(Voxelize, SingleVoxelShortcutAgreesWithTheRasterizer) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(0.2, 11.8), tiny(-0.3, 0.3);
  const int32_t d[3] = {12, 12, 12};
  int answered = 0;
  for (int i = 0; i < 3000; ++i) {
    D3 v[3];
    for (int a = 0; a < 3; ++a) v[0][a] = pos(rng);
    for (int k = 1; k < 3; ++k)
      for (int a = 0; a < 3; ++a) v[k][a] = v[0][a] + tiny(rng);
    if (i % 5 == 1) v[2] = v[1];                                    // a segment
    if (i % 5 == 2) v[1] = v[2] = v[0];                             // a point
    if (i % 7 == 3) v[0][0] = v[1][0] = v[2][0] = std::floor(v[0][0]);  // on a voxel's face
    int32_t ijk[3];
    bool degenerate = false;
    const bool single = voxel::single_voxel(reinterpret_cast<const double(*)[3]>(&v[0][0]), d, ijk, degenerate);
    const voxel::TriangleRaster tr = voxel::setup_triangle(v[0].data(), v[1].data(), v[2].data(), d);
    std::vector<std::array<int32_t, 3>> got;
    voxel::rasterize_triangle(tr, [&](int32_t x, int32_t y, int32_t z) { got.push_back({x, y, z}); });
    if (!single) continue;
    ++answered;
    ASSERT_EQ(got.size(), 1u) << "triangle " << i;
    EXPECT_EQ(got[0], (std::array<int32_t, 3>{ijk[0], ijk[1], ijk[2]})) << "triangle " << i;
    EXPECT_EQ(degenerate, tr.degenerate) << "triangle " << i;
  }
  EXPECT_GT(answered, 500);  // the shortcut is taken (953 of the 3000 here), segments and points too
}

TEST(Voxelize, ZeroAreaTrianglesMarkTheirPointsAndSegments) {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  test::add_triangle(s, {0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0, 0, 1}, m);  // gives the grid its size
  // A point triangle and a segment triangle (collinear, the middle point repeated).
  test::add_triangle(s, {2.3f, 2.2f, 3.1f}, {2.3f, 2.2f, 3.1f}, {2.3f, 2.2f, 3.1f}, {0, 0, 1}, m);
  test::add_triangle(s, {0.2f, 3.3f, 0.7f}, {3.1f, 1.2f, 3.6f}, {0.2f, 3.3f, 0.7f}, {0, 0, 1}, m);
  test::add_triangle(s, {0.5f, 0.5f, 2.f}, {1.5f, 1.5f, 2.f}, {2.5f, 2.5f, 2.f}, {0, 0, 1}, m);  // collinear
  VoxelGrid g;
  VoxelReport rep;
  ASSERT_TRUE(voxelize(s, occupancy_only(20), Context{}, g, &rep).is_ok());
  EXPECT_EQ(rep.degenerate_triangles, 3u);
  EXPECT_TRUE(test::surface_touching(g, 2.3f, 2.2f, 3.1f));
  for (int i = 0; i <= 100; ++i) {
    const float t = i / 100.f;
    EXPECT_TRUE(test::surface_touching(g, 0.2f + t * 2.9f, 3.3f - t * 2.1f, 0.7f + t * 2.9f)) << t;
    EXPECT_TRUE(test::surface_touching(g, 0.5f + t * 2.f, 0.5f + t * 2.f, 2.f)) << t;
  }
  // Every surface voxel meets some triangle (the degenerate ones tested as segments/points).
  for (const SurfaceVoxel& sv : g.surface) {
    const D3 lo{double(sv.ijk[0]), double(sv.ijk[1]), double(sv.ijk[2])}, hi{lo[0] + 1, lo[1] + 1, lo[2] + 1};
    bool any = false;
    for (size_t t = 0; t < s.triangle_count() && !any; ++t) {
      D3 v[3];
      test::scene_triangle_voxels(s, g, t, v);
      any = test::triangle_meets_box(v[0], v[1], v[2], lo, hi, 1e-6) ||
            test::segment_hits_box(v[0], v[1], {lo[0] - 1e-6, lo[1] - 1e-6, lo[2] - 1e-6},
                                   {hi[0] + 1e-6, hi[1] + 1e-6, hi[2] + 1e-6}) ||
            test::segment_hits_box(v[1], v[2], {lo[0] - 1e-6, lo[1] - 1e-6, lo[2] - 1e-6},
                                   {hi[0] + 1e-6, hi[1] + 1e-6, hi[2] + 1e-6});
    }
    EXPECT_TRUE(any) << sv.ijk[0] << "," << sv.ijk[1] << "," << sv.ijk[2];
  }
}

TEST(Voxelize, SceneOfOnePointDoesNotCrash) {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  test::add_triangle(s, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {0, 0, 1}, m);
  VoxelGrid g;
  VoxelSettings vs = occupancy_only(64);
  vs.sdf = true;
  ASSERT_TRUE(voxelize(s, vs, Context{}, g).is_ok());
  EXPECT_EQ(g.voxel_size, 1.f);  // zero extent: 1 m voxels
  EXPECT_EQ(g.dims[0], 3);
  EXPECT_TRUE(test::surface_touching(g, 1, 2, 3));
  EXPECT_EQ(g.sdf.size(), g.space.size());
}

// A closed room whose -x wall has a window, split by a tilted 1-voxel-thin wall: the window side
// is exterior, the far side must stay sealed (interior) — any gap in the thin wall leaks.
Scene split_room(float tilt_y, float tilt_z) {
  Scene s;
  const int m = test::add_material(s, 0.5f, 0.f, true);
  const float L = 4.f;
  // Walls except -x.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      if (axis == 0 && side == 0) continue;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Vec3f p[4];
      const float us[4] = {0, L, L, 0}, vs[4] = {0, 0, L, L};
      for (int k = 0; k < 4; ++k) {
        p[k][axis] = side ? L : 0.f;
        p[k][u] = us[k];
        p[k][v] = vs[k];
      }
      Vec3f n{0, 0, 0};
      n[axis] = side ? -1.f : 1.f;
      test::add_quad(s, p[0], p[1], p[2], p[3], n, m);
    }
  // -x wall with a 1 m window in the middle: four quads around it.
  const float a = 1.5f, b = 2.5f;
  const Vec3f n{1, 0, 0};
  test::add_quad(s, {0, 0, 0}, {0, a, 0}, {0, a, L}, {0, 0, L}, n, m);
  test::add_quad(s, {0, b, 0}, {0, L, 0}, {0, L, L}, {0, b, L}, n, m);
  test::add_quad(s, {0, a, 0}, {0, b, 0}, {0, b, a}, {0, a, a}, n, m);
  test::add_quad(s, {0, a, b}, {0, b, b}, {0, b, L}, {0, a, L}, n, m);
  // Thin wall: plane x = 2 + tilt_y (y - 2) + tilt_z (z - 2), a quad reaching past the room.
  auto wall = [&](float y, float z) { return Vec3f{2.f + tilt_y * (y - 2.f) + tilt_z * (z - 2.f), y, z}; };
  test::add_quad(s, wall(-0.5f, -0.5f), wall(4.5f, -0.5f), wall(4.5f, 4.5f), wall(-0.5f, 4.5f), {1, 0, 0}, m);
  return s;
}

TEST(Voxelize, ThinTiltedWallSeparatesTheTwoSides) {
  const float tilts[][2] = {{0.f, 0.f}, {0.23f, -0.17f}, {0.41f, 0.37f}};
  for (const auto& tilt : tilts) {
    const Scene s = split_room(tilt[0], tilt[1]);
    for (int res : {23, 40, 57}) {
      VoxelGrid g;
      ASSERT_TRUE(voxelize(s, occupancy_only(res), Context{}, g).is_ok());
      size_t near_side = 0, far_side = 0;
      for (int32_t z = 0; z < g.dims[2]; ++z)
        for (int32_t y = 0; y < g.dims[1]; ++y)
          for (int32_t x = 0; x < g.dims[0]; ++x) {
            const auto c = g.voxel_center(x, y, z);
            const float h = g.voxel_size;
            const bool inside_room = c[0] > h && c[0] < 4 - h && c[1] > h && c[1] < 4 - h && c[2] > h && c[2] < 4 - h;
            const float plane = c[0] - (2.f + tilt[0] * (c[1] - 2.f) + tilt[1] * (c[2] - 2.f));
            if (!inside_room || std::fabs(plane) < 1.8f * h) continue;
            const auto sp = static_cast<VoxelSpace>(g.space[size_t(g.linear(x, y, z))]);
            if (plane < 0) {
              EXPECT_EQ(sp, VoxelSpace::Exterior);
              ++near_side;
            } else {
              ASSERT_EQ(sp, VoxelSpace::Interior)
                  << "leak at " << x << "," << y << "," << z << " res " << res << " tilt " << tilt[0] << "," << tilt[1];
              ++far_side;
            }
          }
      EXPECT_GT(near_side, 0u);
      EXPECT_GT(far_side, 0u);
      // No gaps: every x-row through the room's inside meets the wall in a surface voxel.
      for (int32_t z = 2; z < g.dims[2] - 2; ++z)
        for (int32_t y = 2; y < g.dims[1] - 2; ++y) {
          const auto c = g.voxel_center(0, y, z);
          if (c[1] < 0.3f || c[1] > 3.7f || c[2] < 0.3f || c[2] > 3.7f) continue;
          const float xw = 2.f + tilt[0] * (c[1] - 2.f) + tilt[1] * (c[2] - 2.f);
          int32_t ijk[3];
          const float p[3] = {xw, c[1], c[2]};
          ASSERT_TRUE(g.voxel_of(p, ijk));
          EXPECT_EQ(g.space[size_t(g.linear(ijk[0], y, z))], uint8_t(VoxelSpace::Surface));
        }
    }
  }
}

Scene box_on_floor(bool with_top) {
  Scene s;
  const int m = test::add_material(s, 0.5f, 0.f, true);
  test::add_quad(s, {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}, {0, 1, 0}, m);  // floor
  const float h = 0.5f;
  // Four walls and the top of a double-sided box [-h,h] x [0,1] x [-h,h]; no bottom face.
  test::add_quad(s, {-h, 0, -h}, {h, 0, -h}, {h, 1, -h}, {-h, 1, -h}, {0, 0, -1}, m);
  test::add_quad(s, {-h, 0, h}, {h, 0, h}, {h, 1, h}, {-h, 1, h}, {0, 0, 1}, m);
  test::add_quad(s, {-h, 0, -h}, {-h, 0, h}, {-h, 1, h}, {-h, 1, -h}, {-1, 0, 0}, m);
  test::add_quad(s, {h, 0, -h}, {h, 0, h}, {h, 1, h}, {h, 1, -h}, {1, 0, 0}, m);
  if (with_top) test::add_quad(s, {-h, 1, -h}, {h, 1, -h}, {h, 1, h}, {-h, 1, h}, {0, 1, 0}, m);
  return s;
}

struct Voxelized {
  Status status;
  VoxelGrid grid;
  VoxelReport report;
};

// box_on_floor(with_top), occupancy only, 64 voxels across.
Voxelized voxelize_box_on_floor(bool with_top) {
  Voxelized v;
  v.status = voxelize(box_on_floor(with_top), occupancy_only(64), Context{}, v.grid, &v.report);
  return v;
}

TEST(Voxelize, ClosedBoxOnFloorWithoutBottomIsInterior) {
  const Voxelized v = voxelize_box_on_floor(true);
  ASSERT_TRUE(v.status.is_ok());
  const VoxelGrid& g = v.grid;
  const VoxelReport& rep = v.report;
  EXPECT_EQ(test::space_at(g, 0.f, 0.5f, 0.f), VoxelSpace::Interior);
  EXPECT_EQ(test::space_at(g, 1.5f, 0.5f, 1.5f), VoxelSpace::Exterior);
  EXPECT_EQ(test::space_at(g, 0.f, -0.1f, 0.f), VoxelSpace::Exterior);  // under the floor
  // The inside is 1 m x 1 m x 1 m less half a voxel of wall on each side (walls cross voxel
  // middles here; on voxel boundaries they would take two layers: (1/h - 2)^3).
  const double h = g.voxel_size, inner = std::pow(1.0 / h - 1.0, 3);
  EXPECT_NEAR(double(rep.interior_voxels), inner, 0.25 * inner);
  EXPECT_EQ(rep.interior_voxels, test::count_space(g, VoxelSpace::Interior));
  EXPECT_EQ(rep.surface_voxels + rep.interior_voxels + rep.exterior_voxels, g.space.size());
}

TEST(Voxelize, OpenBoxOnFloorIsExterior) {
  const Voxelized v = voxelize_box_on_floor(false);
  ASSERT_TRUE(v.status.is_ok());
  EXPECT_EQ(test::space_at(v.grid, 0.f, 0.5f, 0.f), VoxelSpace::Exterior);
  EXPECT_EQ(v.report.interior_voxels, 0u);
}

Scene busy_scene() {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  test::add_box(s, {-3, -1, -3}, {3, 4, 3}, true, m);
  test::add_sphere(s, {0.3f, 1.1f, -0.2f}, 1.3f, 96, 48, m);  // > 2 chunks of 2048 triangles
  test::add_box(s, {1.f, -1.f, 1.f}, {2.2f, 0.7f, 2.1f}, false, m);
  test::add_triangle(s, {-2, 0, 0}, {-2, 0, 0}, {-1, 1, 1}, {0, 1, 0}, m);
  return s;
}

void expect_same_grid(const VoxelGrid& a, const VoxelGrid& b) {
  ASSERT_EQ(a.dims, b.dims);
  EXPECT_EQ(a.origin, b.origin);
  EXPECT_EQ(a.space, b.space);
  ASSERT_EQ(a.surface.size(), b.surface.size());
  EXPECT_EQ(0, std::memcmp(a.surface.data(), b.surface.data(), a.surface.size() * sizeof(SurfaceVoxel)));
  ASSERT_EQ(a.sdf.size(), b.sdf.size());
  EXPECT_EQ(0, std::memcmp(a.sdf.data(), b.sdf.data(), a.sdf.size() * sizeof(float)));
}

TEST(Voxelize, SameBytesForAnyThreadCount) {
  const Scene s = busy_scene();
  ASSERT_GT(s.triangle_count(), 2 * 2048u);
  VoxelSettings vs;
  vs.resolution = 48;
  VoxelGrid ref;
  Context c1;
  c1.threads = 1;
  ASSERT_TRUE(voxelize(s, vs, c1, ref).is_ok());
  EXPECT_GT(ref.surface.size(), 1000u);
  EXPECT_GT(test::count_space(ref, VoxelSpace::Interior), 0u);  // the solid box and the sphere
  for (unsigned threads : {2u, 3u, 8u}) {
    Context c;
    c.threads = threads;
    VoxelGrid g;
    ASSERT_TRUE(voxelize(s, vs, c, g).is_ok());
    expect_same_grid(ref, g);
  }
}

// The occupancy-only path (no fragment lists) gives the fragment path's grid: the same space,
// surface voxels in the same order with the same fragment counts, and the same report counts.
TEST(Voxelize, OccupancyPathEqualsFragmentPath) {
  const Scene s = busy_scene();
  VoxelSettings with = occupancy_only(48);
  with.channels = true;
  VoxelGrid frag;
  VoxelReport frag_rep;
  Context c1;
  c1.threads = 1;
  ASSERT_TRUE(voxelize(s, with, c1, frag, &frag_rep).is_ok());
  ASSERT_GT(frag.surface.size(), 1000u);
  for (unsigned threads : {1u, 2u, 8u}) {
    Context c;
    c.threads = threads;
    VoxelGrid occ;
    VoxelReport rep;
    ASSERT_TRUE(voxelize(s, occupancy_only(48), c, occ, &rep).is_ok());
    EXPECT_EQ(occ.space, frag.space);
    ASSERT_EQ(occ.surface.size(), frag.surface.size());
    for (size_t i = 0; i < occ.surface.size(); ++i) {
      ASSERT_EQ(0, std::memcmp(occ.surface[i].ijk, frag.surface[i].ijk, sizeof occ.surface[i].ijk)) << i;
      ASSERT_EQ(occ.surface[i].fragments, frag.surface[i].fragments) << i;
    }
    EXPECT_EQ(rep.fragments, frag_rep.fragments);
    EXPECT_EQ(rep.degenerate_triangles, frag_rep.degenerate_triangles);
    EXPECT_EQ(rep.interior_voxels, frag_rep.interior_voxels);
  }
}

TEST(Voxelize, RefusesAbsurdSizesWithTheFigure) {
  const Scene s = box_on_floor(true);
  VoxelSettings vs = occupancy_only(128);
  vs.voxel_size = 1e-3f;  // 4000^3 voxels
  VoxelGrid g;
  Status st = voxelize(s, vs, Context{}, g);
  ASSERT_FALSE(st.is_ok());
  EXPECT_EQ(st.code(), ExitCode::BadArguments);
  EXPECT_NE(st.what().find("needs about"), std::string::npos) << st.message();
  EXPECT_NE(st.what().find("GiB, over the "), std::string::npos) << st.message();
  EXPECT_TRUE(g.empty());
  vs.voxel_size = 1e-12f;  // beyond 2^30 voxels per axis
  st = voxelize(s, vs, Context{}, g);
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(st.what().find("2^30"), std::string::npos) << st.message();
  vs.voxel_size = -1.f;
  EXPECT_EQ(voxelize(s, vs, Context{}, g).code(), ExitCode::BadArguments);
  vs.voxel_size = 0.f;
  vs.resolution = 0;
  EXPECT_EQ(voxelize(s, vs, Context{}, g).code(), ExitCode::BadArguments);
  vs.resolution = 64;
  vs.max_bytes = 1000;
  st = voxelize(s, vs, Context{}, g);
  EXPECT_EQ(st.code(), ExitCode::BadArguments);
  Scene empty;
  EXPECT_EQ(voxelize(empty, occupancy_only(8), Context{}, g).code(), ExitCode::InvalidInput);
}

TEST(Voxelize, EstimateCoversTheFragments) {
  const Scene s = busy_scene();
  VoxelSettings vs = occupancy_only(64);
  VoxelGrid g;
  VoxelReport rep;
  ASSERT_TRUE(voxelize(s, vs, Context{}, g, &rep).is_ok());
  const double used = double(g.space.size()) + double(rep.fragments) * 2 * sizeof(voxel::Fragment) +
                      double(g.surface.size()) * sizeof(SurfaceVoxel);
  EXPECT_GE(double(rep.estimated_bytes), used);
}

}  // namespace
}  // namespace gibake
