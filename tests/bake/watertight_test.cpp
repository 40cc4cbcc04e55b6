// The CPU tracer is watertight along edges: rays from inside a closed mesh aimed at its shared
// edges all hit it (Embree's robust mode; without it some slip through). A bake that let such rays
// through would carry light from outside a closed room into it (tests/bake/edge_rays.h). Rays aimed
// exactly at a corner are left out here: Embree's robust test still lets a few of those through.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/scene/prepare.h"
#include "tests/bake/edge_rays.h"
#include "tests/bake/scene_builders.h"

using namespace gibake;

namespace {

TEST(Watertight, IcosphereBuilderIsClosedAndFacesOut) {
  Scene s;
  test::add_icosphere(s, {1.f, 2.f, 3.f}, 2.f, 3, test::add_material(s, 0.5f));
  ASSERT_EQ(s.triangle_count(), 20u * 64u);
  EXPECT_EQ(s.vertex_count(), 642u);  // V - E + F = 2 with E = 3F / 2: every edge shared by two faces
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    const float* p[3];
    for (int k = 0; k < 3; ++k) p[k] = &s.positions[size_t(s.indices[t * 3 + size_t(k)]) * 3];
    const kernels::float3 a{p[0][0], p[0][1], p[0][2]}, b{p[1][0], p[1][1], p[1][2]}, c{p[2][0], p[2][1], p[2][2]};
    const kernels::float3 out = (a + b + c) * (1.f / 3.f) - kernels::float3{1.f, 2.f, 3.f};
    EXPECT_GT(kernels::dot(kernels::cross(b - a, c - a), out), 0.f) << "triangle " << t;
  }
}

TEST(Watertight, RaysAtSharedEdgesNeverEscapeAClosedMesh) {
  Scene s;
  // Off the origin and at a room's size, so that the vertices' coordinates round unevenly.
  const Vec3f centre{3.7f, -1.3f, 0.6f};
  test::add_icosphere(s, centre, 10.f, 5, test::add_material(s, 0.5f));
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(s, Context{}, prepared));
  const std::vector<test::EdgeRay> rays = test::rays_at_edges(s, centre, 8.f, 200000, 3);
  size_t missed = 0, unblocked = 0;
  for (const test::EdgeRay& r : rays) {
    missed += prepared->intersect(r.org, r.dir, 0.f, INFINITY).t < 0.f;
    unblocked += !prepared->occluded(r.org, r.dir, 0.f, INFINITY);
  }
  EXPECT_EQ(missed, 0u) << "of " << rays.size() << " closest-hit rays";
  EXPECT_EQ(unblocked, 0u) << "of " << rays.size() << " shadow rays";
}

}  // namespace
