// Paths' first hits kept unread and ended later in a probe field (bake/preview/ended_path_hits.h):
// ending the kept hits in a field must give what tracing the same paths and ending them in that
// field gives (to the kept weights' half-float rounding and the normals' 16 bits), in any field and
// for any thread count.
#include "bake/preview/ended_path_hits.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bake/preview/reconstruction_check.h"
#include "bake/scene/prepare.h"
#include "tests/bake/scene_builders.h"

namespace gibake {
namespace {

using kernels::float3;

// A grey floor, ceiling and wall facing a glowing wall: the floor's paths land on grey surfaces
// (ended there) and on the glowing wall (which a path does not end at).
Scene room() {
  Scene scene;
  test::add_quad(scene, {2.f, 0.f, -2.f}, {2.f, 0.f, 2.f}, {2.f, 2.f, 2.f}, {2.f, 2.f, -2.f}, {-1, 0, 0},
                 test::add_material(scene, 0.f, 10.f));
  const int grey = test::add_material(scene, 0.5f);
  test::add_quad(scene, {-2.f, 0.f, -2.f}, {-2.f, 0.f, 2.f}, {2.f, 0.f, 2.f}, {2.f, 0.f, -2.f}, {0, 1, 0}, grey);
  test::add_quad(scene, {-2.f, 2.f, -2.f}, {2.f, 2.f, -2.f}, {2.f, 2.f, 2.f}, {-2.f, 2.f, 2.f}, {0, -1, 0}, grey);
  test::add_quad(scene, {-2.f, 0.f, 2.f}, {-2.f, 0.f, -2.f}, {-2.f, 2.f, -2.f}, {-2.f, 2.f, 2.f}, {1, 0, 0}, grey);
  return scene;
}

// Light that changes with place and facing, so that a hit's place and normal both count.
struct Field final : ProbeField {
  float scale = 1.f;
  float3 irradiance(const float3& p, const float3& n) const override {
    return float3{1.f + p.x * p.x, 2.f + n.y, 3.f + 0.5f * p.y} * scale;
  }
};

struct Traced {
  std::vector<SurfaceLight> light;
  EndedPathHits kept;
};

// The paths of 24 floor points and an invalid one, ended in `field` (`keep` false) or kept unread.
Traced trace(const PreparedScene& prepared, const ProbeField& field, bool keep, const Context& ctx) {
  std::vector<VisibleSurface> points;
  for (int i = 0; i < 24; ++i)
    points.push_back(VisibleSurface{true, {-1.8f + 0.15f * float(i), 0.f, 0.1f * float(i % 5)}, {0, 1, 0}, {0, 1, 0}});
  points.push_back(VisibleSurface{});  // not valid: nothing kept, nothing traced
  Traced out;
  EXPECT_TRUE(trace_surface_irradiance(prepared, TextureLod{}, "{}", points, 64, 11, nullptr, ctx, out.light, &field,
                                       true, 3, keep ? &out.kept : nullptr)
                  .is_ok());
  return out;
}

std::unique_ptr<PreparedScene> prepare(const Scene& scene) {
  std::unique_ptr<PreparedScene> prepared;
  EXPECT_TRUE(PreparedScene::create(scene, Context{}, prepared).is_ok());
  return prepared;
}

TEST(EndedPathHits, EndedAgainInAFieldIsTracingThemEndedInIt) {
  const Scene scene = room();
  const std::unique_ptr<PreparedScene> prepared = prepare(scene);
  Field first, second;
  second.scale = 3.f;
  const Traced a = trace(*prepared, first, true, Context{});
  const Traced b = trace(*prepared, second, false, Context{});
  ASSERT_TRUE(a.kept.complete);
  EXPECT_FALSE(b.kept.complete);
  ASSERT_EQ(a.kept.points.size(), 25u);
  EXPECT_EQ(a.kept.points[24].rays, 0u);
  size_t hits = 0;
  for (const EndedPathHits::Point& p : a.kept.points) hits += p.hits.size();
  EXPECT_GT(hits, 24u * 64u / 4);  // most of the floor's paths land on grey surfaces

  std::vector<SurfaceLight> again = a.light;
  end_kept_paths(a.kept, second, Context{}, again);
  for (size_t i = 0; i < 24; ++i) {
    EXPECT_EQ(a.light[i].probe_lit.y, 0.f);  // kept, not read in the first field
    // The whole paths are the same paths in both traces.
    EXPECT_EQ(a.light[i].irradiance.x, b.light[i].irradiance.x);
    EXPECT_EQ(again[i].irradiance.x, a.light[i].irradiance.x);
    EXPECT_NEAR(again[i].probe_lit.y, b.light[i].probe_lit.y, 2e-3 * b.light[i].probe_lit.y) << i;
    for (int h = 0; h < 2; ++h)
      EXPECT_NEAR(again[i].probe_half[h], b.light[i].probe_half[h], 2e-3 * b.light[i].probe_half[h]) << i;
  }
  // And in the field they were traced with (whose light is a third of the second's).
  std::vector<SurfaceLight> first_read = a.light;
  end_kept_paths(a.kept, first, Context{}, first_read);
  const Traced c = trace(*prepared, first, false, Context{});
  for (size_t i = 0; i < 24; ++i)
    EXPECT_NEAR(first_read[i].probe_lit.y, c.light[i].probe_lit.y, 2e-3 * c.light[i].probe_lit.y) << i;
}

TEST(EndedPathHits, SameBytesForAnyThreadCount) {
  const Scene scene = room();
  const std::unique_ptr<PreparedScene> prepared = prepare(scene);
  Field first, second;
  second.scale = 0.5f;
  Context one, four;
  one.threads = 1;
  four.threads = 4;
  const Traced a = trace(*prepared, first, true, one);
  const Traced b = trace(*prepared, first, true, four);
  std::vector<SurfaceLight> x = a.light, y = b.light;
  end_kept_paths(a.kept, second, one, x);
  end_kept_paths(b.kept, second, four, y);
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i].probe_lit.x, y[i].probe_lit.x);
    EXPECT_EQ(x[i].probe_lit.z, y[i].probe_lit.z);
    EXPECT_EQ(x[i].probe_half[0], y[i].probe_half[0]);
    EXPECT_EQ(x[i].probe_half[1], y[i].probe_half[1]);
  }
}

}  // namespace
}  // namespace gibake
