// Mesh diagnostics and the closed-mesh inside tester on small hand-made soups.
#include "io/inspect/mesh_diagnostics.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <initializer_list>
#include <thread>
#include <vector>

namespace gibake {
namespace {

struct Soup {
  std::vector<float> positions;
  std::vector<uint32_t> indices;

  uint32_t vertex(float x, float y, float z) {
    positions.insert(positions.end(), {x, y, z});
    return uint32_t(positions.size() / 3 - 1);
  }
  void tri(uint32_t a, uint32_t b, uint32_t c) { indices.insert(indices.end(), {a, b, c}); }
  // A quad with its own four vertices (flat shading style: welding must join them).
  void quad(const std::array<float, 3> (&c)[4]) {
    uint32_t v[4];
    for (int i = 0; i < 4; ++i) v[i] = vertex(c[i][0], c[i][1], c[i][2]);
    tri(v[0], v[1], v[2]);
    tri(v[0], v[2], v[3]);
  }
  MeshDiagnostics diagnose(bool self_intersections = false) const {
    MeshDiagnosticsOptions options;
    options.check_self_intersections = self_intersections;
    return diagnose_mesh(positions.data(), positions.size() / 3, indices.data(), indices.size() / 3,
                         options);
  }
  ClosedMeshInsideTester tester() const {
    return ClosedMeshInsideTester(positions.data(), positions.size() / 3, indices.data(),
                                  indices.size() / 3);
  }
};

// Axis-aligned box [lo, hi]^3 with outward CCW faces, each face with its own vertices.
// `faces` limits how many of the six faces are written (the -Z face is left out first).
void add_box(Soup& s, float lo, float hi, int faces = 6, float dx = 0.f) {
  const float a = lo + dx, b = hi + dx;
  const std::array<float, 3> quads[6][4] = {
      {{a, lo, hi}, {b, lo, hi}, {b, hi, hi}, {a, hi, hi}},  // +Z
      {{b, lo, lo}, {b, hi, lo}, {b, hi, hi}, {b, lo, hi}},  // +X
      {{a, lo, lo}, {a, lo, hi}, {a, hi, hi}, {a, hi, lo}},  // -X
      {{a, hi, lo}, {a, hi, hi}, {b, hi, hi}, {b, hi, lo}},  // +Y
      {{a, lo, lo}, {b, lo, lo}, {b, lo, hi}, {a, lo, hi}},  // -Y
      {{a, lo, lo}, {a, hi, lo}, {b, hi, lo}, {b, lo, lo}},  // -Z
  };
  for (int f = 0; f < faces; ++f) s.quad(quads[f]);
}

// A count the test states: the field's name (for the failure message), the field and its value.
struct Count {
  const char* name;
  uint64_t MeshDiagnostics::*field;
  uint64_t expected;
};
#define COUNT(field, value) Count{#field, &MeshDiagnostics::field, value}

void expect_counts(const MeshDiagnostics& d, std::initializer_list<Count> counts) {
  for (const Count& c : counts) EXPECT_EQ(d.*c.field, c.expected) << c.name;
}

TEST(MeshDiagnostics, ClosedCube) {
  Soup s;
  add_box(s, -1.f, 1.f);
  const MeshDiagnostics d = s.diagnose(true);
  expect_counts(d, {COUNT(triangles, 12), COUNT(input_vertices, 24), COUNT(welded_vertices, 8),
                    COUNT(edges, 18), COUNT(border_edges, 0), COUNT(non_manifold_edges, 0),
                    COUNT(inconsistent_edges, 0), COUNT(degenerate_triangles, 0), COUNT(components, 1),
                    COUNT(closed_components, 1), COUNT(inward_closed_components, 0)});
  EXPECT_TRUE(d.self_intersections_checked);
  EXPECT_TRUE(d.self_intersections_complete);
  EXPECT_EQ(d.self_intersecting_pairs, 0u);
  EXPECT_TRUE(d.all_closed());
}

TEST(MeshDiagnostics, OpenBoxHasFourBorderEdges) {
  Soup s;
  add_box(s, -1.f, 1.f, 5);
  const MeshDiagnostics d = s.diagnose();
  expect_counts(d, {COUNT(border_edges, 4), COUNT(non_manifold_edges, 0), COUNT(components, 1),
                    COUNT(closed_components, 0)});
  EXPECT_FALSE(d.all_closed());
}

TEST(MeshDiagnostics, ThreeTrianglesOnOneEdgeAreNonManifold) {
  Soup s;
  const uint32_t a = s.vertex(0, 0, 0), b = s.vertex(1, 0, 0);
  s.tri(a, b, s.vertex(0.5f, 1, 0));
  s.tri(b, a, s.vertex(0.5f, -1, 0));
  s.tri(a, b, s.vertex(0.5f, 0, 1));
  const MeshDiagnostics d = s.diagnose();
  expect_counts(d, {COUNT(non_manifold_edges, 1), COUNT(border_edges, 6), COUNT(components, 1),
                    COUNT(closed_components, 0)});
}

TEST(MeshDiagnostics, DegenerateTrianglesAreCounted) {
  Soup s;
  add_box(s, -1.f, 1.f);
  const uint32_t a = s.vertex(5, 5, 5), b = s.vertex(6, 5, 5), c = s.vertex(7, 5, 5);
  s.tri(a, b, c);                  // collinear: zero area
  s.tri(a, a, b);                  // repeated index
  s.tri(b, c, s.vertex(6, 5, 5));  // repeated after welding
  const MeshDiagnostics d = s.diagnose();
  expect_counts(d, {COUNT(zero_area_triangles, 1), COUNT(repeated_vertex_triangles, 2),
                    COUNT(degenerate_triangles, 3), COUNT(closed_components, 1)});  // the cube is still closed
  EXPECT_FALSE(d.all_closed());
}

TEST(MeshDiagnostics, FlippedFaceIsInconsistent) {
  Soup s;
  add_box(s, -1.f, 1.f);
  std::swap(s.indices[1], s.indices[2]);  // flip one triangle of the +Z face
  const MeshDiagnostics d = s.diagnose();
  expect_counts(d, {COUNT(inconsistent_edges, 3), COUNT(border_edges, 0), COUNT(closed_components, 0)});
}

TEST(MeshDiagnostics, InvalidIndicesAreIgnored) {
  Soup s;
  add_box(s, -1.f, 1.f);
  s.tri(0, 1, 999);
  const MeshDiagnostics d = s.diagnose();
  expect_counts(d, {COUNT(triangles, 13), COUNT(invalid_triangles, 1), COUNT(closed_components, 1)});
}

TEST(MeshDiagnostics, InwardRoomAndSeparateComponents) {
  Soup room;
  add_box(room, -1.f, 1.f);
  for (size_t t = 0; t < room.indices.size(); t += 3)
    std::swap(room.indices[t + 1], room.indices[t + 2]);
  add_box(room, 3.f, 4.f);
  const MeshDiagnostics d = room.diagnose();
  expect_counts(d, {COUNT(components, 2), COUNT(closed_components, 2), COUNT(inward_closed_components, 1)});
}

TEST(MeshDiagnostics, SelfIntersectionsFound) {
  Soup s;
  add_box(s, -1.f, 1.f);
  add_box(s, 0.f, 2.f, 6, 0.5f);  // overlaps the first cube
  const MeshDiagnostics d = s.diagnose(true);
  EXPECT_TRUE(d.self_intersections_complete);
  EXPECT_GT(d.self_intersecting_pairs, 0u);
  const MeshDiagnostics unchecked = s.diagnose(false);
  EXPECT_FALSE(unchecked.self_intersections_checked);
}

TEST(MeshDiagnostics, EmptySoup) {
  const MeshDiagnostics d = diagnose_mesh(nullptr, 0, nullptr, 0);
  EXPECT_EQ(d.components, 0u);
  EXPECT_FALSE(d.all_closed());
}

TEST(ClosedMeshInsideTester, CubeInsideOutside) {
  Soup s;
  add_box(s, -1.f, 1.f);
  const ClosedMeshInsideTester tester = s.tester();
  ASSERT_TRUE(tester.valid());
  EXPECT_EQ(tester.component_count(), 1u);
  const float centre[3] = {0, 0, 0}, near_corner[3] = {0.9f, -0.9f, 0.9f};
  const float outside[3] = {3, 0, 0}, beside[3] = {1.5f, 0.5f, 0.5f};
  const float on_face[3] = {1, 0.25f, 0.25f};
  EXPECT_EQ(tester.classify(centre), 1);
  EXPECT_EQ(tester.classify(near_corner), 1);
  EXPECT_EQ(tester.classify(outside), -1);
  EXPECT_EQ(tester.classify(beside), -1);
  EXPECT_EQ(tester.classify(on_face), 0);
}

TEST(ClosedMeshInsideTester, OverlappingSolidsAndOpenParts) {
  Soup s;
  add_box(s, -1.f, 1.f);
  add_box(s, 0.f, 2.f, 6, 0.5f);  // overlaps: parity over both would say "outside" here
  add_box(s, 5.f, 6.f, 5);        // open: not a solid
  const ClosedMeshInsideTester tester = s.tester();
  EXPECT_EQ(tester.component_count(), 2u);
  const float in_both[3] = {0.75f, 0.5f, 0.5f}, in_open[3] = {5.5f, 5.5f, 5.5f};
  EXPECT_EQ(tester.classify(in_both), 1);
  EXPECT_EQ(tester.classify(in_open), -1);
}

TEST(ClosedMeshInsideTester, InvalidWithoutClosedComponents) {
  Soup s;
  add_box(s, -1.f, 1.f, 5);
  const ClosedMeshInsideTester tester = s.tester();
  EXPECT_FALSE(tester.valid());
  const float centre[3] = {0, 0, 0};
  EXPECT_EQ(tester.classify(centre), 0);
  const ClosedMeshInsideTester empty;
  EXPECT_FALSE(empty.valid());
  EXPECT_EQ(empty.classify(centre), 0);
}

// classify() of points 0..n-1 (point(k, xyz)), the points dealt round-robin to `threads` threads.
template <class PointFn>
std::vector<int> classify_points(const ClosedMeshInsideTester& tester, int n, const PointFn& point, int threads) {
  std::vector<int> out(static_cast<size_t>(n));
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (int k = t; k < n; k += threads) {
        float p[3];
        point(k, p);
        out[size_t(k)] = tester.classify(p);
      }
    });
  for (std::thread& th : pool) th.join();
  return out;
}

TEST(ClosedMeshInsideTester, ConcurrentQueriesAgree) {
  Soup s;
  for (int i = 0; i < 8; ++i) add_box(s, 0.f, 1.f, 6, 2.f * float(i));
  const ClosedMeshInsideTester tester = s.tester();
  ASSERT_EQ(tester.component_count(), 8u);
  const auto point = [](int k, float out[3]) {
    out[0] = -1.f + 0.0173f * float(k % 1000);
    out[1] = 0.05f + 0.1f * float((k / 1000) % 9);
    out[2] = 0.5f;
  };
  const int n = 9000;
  const std::vector<int> serial = classify_points(tester, n, point, 1);
  EXPECT_EQ(serial, classify_points(tester, n, point, 4));
  int inside = 0;
  for (int v : serial) inside += v == 1;
  EXPECT_GT(inside, 0);
  EXPECT_LT(inside, n);
}

// On demand, solids are built by the queries that reach them, from several threads at once
// (call_once per solid); the answers must be those of the tester with every solid built.
TEST(ClosedMeshInsideTester, OnDemandAnswersAsUpFront) {
  Soup s;
  for (int i = 0; i < 6; ++i) add_box(s, 0.f, 1.f + 0.25f * float(i), 6, 2.f * float(i));
  add_box(s, 20.f, 21.f, 5);  // open
  const ClosedMeshInsideTester up_front = s.tester();
  const ClosedMeshInsideTester on_demand(s.positions.data(), s.positions.size() / 3, s.indices.data(),
                                         s.indices.size() / 3, SolidBuild::on_demand);
  const auto point = [](int k, float out[3]) {
    out[0] = -1.f + 0.0231f * float(k % 1000);
    out[1] = 0.05f + 0.2f * float((k / 1000) % 9);
    out[2] = 0.5f;
  };
  const int n = 9000;
  EXPECT_EQ(classify_points(up_front, n, point, 1), classify_points(on_demand, n, point, 4));
  EXPECT_TRUE(on_demand.valid());
  EXPECT_EQ(on_demand.component_count(), up_front.component_count());
  EXPECT_EQ(up_front.component_count(), 6u);
  Soup open;
  add_box(open, -1.f, 1.f, 5);
  const ClosedMeshInsideTester none(open.positions.data(), open.positions.size() / 3, open.indices.data(),
                                    open.indices.size() / 3, SolidBuild::on_demand);
  EXPECT_FALSE(none.valid());
}

// build_near builds the solids whose box (grown by the pad) holds a point, and nothing else.
TEST(ClosedMeshInsideTester, BuildNearBuildsTheSolidsAroundThePoints) {
  Soup s;
  for (int i = 0; i < 6; ++i) add_box(s, 0.f, 1.f + 0.25f * float(i), 6, 2.f * float(i));  // x from 2i
  const ClosedMeshInsideTester up_front = s.tester();
  const ClosedMeshInsideTester t(s.positions.data(), s.positions.size() / 3, s.indices.data(), s.indices.size() / 3,
                                 SolidBuild::on_demand);
  const float zero[3] = {0.f, 0.f, 0.f}, reach[3] = {0.6f, 0.f, 0.f};
  const float in_box1[3] = {2.5f, 0.5f, 0.5f}, far[3] = {100.f, 0.5f, 0.5f};
  const float between[3] = {3.5f, 0.5f, 0.5f};  // 0.25 past box 1 (to 3.25), 0.5 before box 2
  EXPECT_EQ(t.build_near(in_box1, 1, zero), 1u);
  EXPECT_EQ(t.build_near(far, 1, zero), 0u);
  EXPECT_EQ(t.build_near(between, 1, zero), 0u);
  EXPECT_EQ(t.build_near(between, 1, reach), 2u);
  const float both[6] = {2.5f, 0.5f, 0.5f, 100.f, 0.5f, 0.5f};
  EXPECT_EQ(t.build_near(both, 2, zero), 1u);
  // Answers are the same whatever was built ahead.
  const auto point = [](int k, float out[3]) {
    out[0] = -1.f + 0.0231f * float(k % 1000);
    out[1] = 0.05f + 0.2f * float((k / 1000) % 9);
    out[2] = 0.5f;
  };
  EXPECT_EQ(classify_points(up_front, 9000, point, 1), classify_points(t, 9000, point, 4));
}

TEST(ClosedMeshInsideTester, FromScene) {
  Soup s;
  add_box(s, -1.f, 1.f);
  Scene scene;
  scene.positions = s.positions;
  scene.indices = s.indices;
  ClosedMeshInsideTester tester(scene);
  ClosedMeshInsideTester moved = std::move(tester);
  const float centre[3] = {0, 0, 0}, nan_point[3] = {0, NAN, 0};
  EXPECT_EQ(moved.classify(centre), 1);
  EXPECT_EQ(moved.classify(nan_point), 0);
  EXPECT_FALSE(tester.valid());  // NOLINT(bugprone-use-after-move): moved-from is empty
  EXPECT_EQ(diagnose_mesh(scene).closed_components, 1u);
}

}  // namespace
}  // namespace gibake
