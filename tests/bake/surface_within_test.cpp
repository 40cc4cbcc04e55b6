// PreparedScene::surface_within, the near volumes' test (bake/ddgi/near_surface.h).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "bake/scene/prepare.h"
#include "io/context.h"
#include "tests/bake/scene_builders.h"

using namespace gibake;

// PreparedScene::surface_within (the near volumes' test) against the distance to one triangle,
// (0,0,0), (2,0,0), (0,2,0), known in closed form in each of its regions: a vertex, an edge, the
// face; a point just inside and just outside each distance.
TEST(SurfaceWithin, MatchesTheDistanceToATriangleInEveryRegion) {
  Scene scene;
  test::add_triangle(scene, {0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, test::add_material(scene, 0.5f));
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared).is_ok());
  struct Case {
    kernels::float3 p;
    float distance;
    const char* region;
  };
  const Case cases[] = {
      {{-0.6f, -0.8f, 0.f}, 1.f, "vertex (0,0,0)"},   {{2.f, -0.3f, 0.4f}, 0.5f, "vertex (2,0,0)"},
      {{-0.3f, 1.f, 0.4f}, 0.5f, "edge x = 0"},       {{1.5f, 1.5f, 0.f}, std::sqrt(0.5f), "the hypotenuse"},
      {{0.5f, 0.5f, -0.7f}, 0.7f, "the face, below"}, {{0.5f, 0.5f, 0.25f}, 0.25f, "the face, above"},
  };
  for (const Case& c : cases) {
    EXPECT_TRUE(prepared->surface_within(c.p, c.distance * 1.01f)) << c.region;
    EXPECT_FALSE(prepared->surface_within(c.p, c.distance * 0.99f)) << c.region;
  }
}
