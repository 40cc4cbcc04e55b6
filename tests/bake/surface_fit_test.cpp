// The surface fit (bake/ddgi/surface_fit.h) against light known without the bake: a black floor
// beside a glowing wall, where the floor's irradiance grows steeply towards the wall (the
// integral of L cos cos / r^2 over the wall, summed numerically here) and probes half a metre apart
// interpolate it poorly. Fitted to points whose light the reference path tracer computes, the
// sampler must come far closer to the numeric answer at other points of the floor. Points the
// probes already read right must leave the atlas as it was, and the fit must not depend on the
// thread count.
#include "bake/ddgi/surface_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/preview/reconstruction_check.h"
#include "bake/scene/prepare.h"
#include "gibake/loader.hpp"
#include "kernels/ray_gen.h"
#include "tests/bake/loader_file.h"
#include "tests/bake/scene_builders.h"

namespace gibake {
namespace {

using kernels::float3;

constexpr float kRadiance = 10.f;  // cd/m^2, the wall's
constexpr float kWallX = 2.f, kWallHeight = 2.f, kWallHalf = 2.f;

Scene wall_and_floor() {
  Scene scene;
  test::add_quad(scene, {kWallX, 0.f, -kWallHalf}, {kWallX, 0.f, kWallHalf}, {kWallX, kWallHeight, kWallHalf},
                 {kWallX, kWallHeight, -kWallHalf}, {-1, 0, 0}, test::add_material(scene, 0.f, kRadiance));
  test::add_quad(scene, {-2.f, 0.f, -2.f}, {-2.f, 0.f, 2.f}, {kWallX, 0.f, 2.f}, {kWallX, 0.f, -2.f}, {0, 1, 0},
                 test::add_material(scene, 0.f));
  return scene;
}

// Irradiance (lux) at floor point (x, 0, z) facing up: L cos(floor) cos(wall) / r^2 summed over a
// 400 x 400 midpoint grid of the wall.
double floor_irradiance(double x, double z) {
  const int n = 400;
  const double dy = kWallHeight / n, dz = 2.0 * kWallHalf / n;
  double sum = 0.0;
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < n; ++k) {
      const double wy = (j + 0.5) * dy, wz = -kWallHalf + (k + 0.5) * dz;
      const double rx = kWallX - x, ry = wy, rz = wz - z;
      const double r2 = rx * rx + ry * ry + rz * rz;
      sum += (ry / std::sqrt(r2)) * (rx / std::sqrt(r2)) / r2 * dy * dz;
    }
  return kRadiance * sum;
}

DdgiSettings probe_settings() {
  DdgiSettings s;
  s.rays = 1024;
  s.target_error = 0.f;
  s.bounces = 1;
  s.cgal_check = false;
  s.relocate = false;
  s.grid.explicit_bounds = true;  // probes 0.5 m apart, the lowest row 0.25 m above the floor
  s.grid.grid_min = {-1.5f, 0.25f, -1.5f};
  s.grid.grid_max = {1.5f, 1.25f, 1.5f};
  s.grid.counts = {7, 3, 7};
  return s;
}

// Floor points facing up, jittered over x in [-1.5, 1.75], z in [-1, 1].
std::vector<float3> floor_points(uint64_t seed, int count) {
  std::vector<float3> out;
  for (int i = 0; i < count; ++i) {
    const uint64_t key = kernels::rng_hash(seed, uint64_t(i), 0, 0);
    out.push_back(float3{-1.5f + 3.25f * kernels::rng_uniform(key, 0), 0.f, -1.f + 2.f * kernels::rng_uniform(key, 1)});
  }
  return out;
}

float luminance(const loader::Rgb& e) { return 0.2126f * e[0] + 0.7152f * e[1] + 0.0722f * e[2]; }

// Mean |sampled / truth - 1| over the points.
double mean_error(const DdgiResult& result, const std::vector<float3>& points, const std::vector<double>& truth) {
  loader::BakeFile file;
  test::open_in_loader(result, file);
  double sum = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    loader::Rgb e{};
    file.sample_ddgi({points[i].x, points[i].y, points[i].z}, {0.f, 1.f, 0.f}, e);
    sum += std::fabs(luminance(e) / truth[i] - 1.0);
  }
  return sum / double(points.size());
}

struct Baked {
  Scene scene;
  DdgiResult result;
};

const Baked& baked() {
  static const Baked* b = [] {
    auto* out = new Baked{wall_and_floor(), {}};
    DdgiReport report;
    EXPECT_TRUE(bake_ddgi(out->scene, probe_settings(), Context{}, out->result, report).is_ok());
    return out;
  }();
  return *b;
}

// The fit's samples: the floor points' light from the reference path tracer, as the stage traces it.
std::vector<SurfaceFitSample> traced_samples(const Baked& b, const std::vector<float3>& points, uint32_t paths) {
  std::unique_ptr<PreparedScene> prepared;
  EXPECT_TRUE(PreparedScene::create(b.scene, Context{}, prepared).is_ok());
  std::vector<VisibleSurface> surfaces;
  for (const float3& p : points) surfaces.push_back(VisibleSurface{true, p, {0.f, 1.f, 0.f}, {0.f, 1.f, 0.f}});
  std::vector<SurfaceLight> light;
  EXPECT_TRUE(trace_surface_irradiance(*prepared, TextureLod{}, b.result.settings_json, surfaces, paths, 7, nullptr,
                                       Context{}, light)
                  .is_ok());
  std::vector<SurfaceFitSample> samples;
  for (size_t i = 0; i < points.size(); ++i) {
    const float3& e = light[i].irradiance;
    const float lum = 0.2126f * e.x + 0.7152f * e.y + 0.0722f * e.z;
    const float standard_error = 0.5f * std::fabs(light[i].half[0] - light[i].half[1]);
    const float rel = lum > 0.f ? standard_error / lum : 0.f;
    samples.push_back(SurfaceFitSample{points[i], {0.f, 1.f, 0.f}, lum, rel * rel});
  }
  return samples;
}

TEST(SurfaceFit, BringsTheSamplerToTheLightOfAFloorBesideAGlowingWall) {
  const Baked& b = baked();
  const std::vector<float3> held_out = floor_points(2, 400);
  std::vector<double> truth;
  for (const float3& p : held_out) truth.push_back(floor_irradiance(p.x, p.z));
  // The path tracer the fit reads agrees with the numeric integral: within 3% at 16384 paths a point
  // (its noise there is under 1%).
  const std::vector<float3> few(held_out.begin(), held_out.begin() + 20);
  const std::vector<SurfaceFitSample> check = traced_samples(b, few, 16384);
  for (size_t i = 0; i < few.size(); ++i) EXPECT_NEAR(check[i].truth, truth[i], 0.03 * truth[i]) << i;

  DdgiResult fitted = b.result;
  loader::BakeFile file;
  test::open_in_loader(fitted, file);
  SurfaceFitReport report;
  ASSERT_TRUE(fit_irradiance_atlases(file, traced_samples(b, floor_points(1, 3000), 128), SurfaceFitSettings{},
                                     {&fitted}, Context{}, report)
                  .is_ok());
  const double before = mean_error(b.result, held_out, truth), after = mean_error(fitted, held_out, truth);
  std::printf("%s\nheld-out floor points: mean |sampled / truth - 1| %.3f before, %.3f after\n",
              surface_fit_summary(report).c_str(), before, after);
  EXPECT_GT(before, 0.08) << "the probes already read the floor right: the test shows nothing";
  EXPECT_LT(after, 0.5 * before);
  EXPECT_EQ(report.used, 3000u);
}

// The pull on a texel's own deviation is SurfaceFitSettings::lambda at kLambdaPaths paths a point
// and falls in proportion as the paths grow (the rule docs/BENCHMARKS.md "The texels' own pull"
// measured): `final`'s 512 paths take a quarter of the default level's.
TEST(SurfaceFit, TheTexelsOwnPullFallsAsThePointsPathsGrow) {
  SurfaceFitSettings s;
  s.paths = kLambdaPaths;
  EXPECT_DOUBLE_EQ(texel_prior(s), double(s.lambda));
  s.paths = 512;
  EXPECT_DOUBLE_EQ(texel_prior(s), 0.25 * double(s.lambda));
  s.paths = 0;  // no paths: as one
  EXPECT_DOUBLE_EQ(texel_prior(s), double(s.lambda) * kLambdaPaths);
}

// Samples whose truth is what the sampler reads already: every gain stays 1 (to the solver's
// tolerance), so the atlas keeps its values; and the fit's bytes are the same for 1 and 2 threads.
TEST(SurfaceFit, PointsReadRightKeepTheAtlasAndThreadsDoNotMatter) {
  const Baked& b = baked();
  loader::BakeFile file;
  test::open_in_loader(b.result, file);
  std::vector<SurfaceFitSample> exact;
  for (const float3& p : floor_points(3, 500)) {
    loader::Rgb e{};
    file.sample_ddgi({p.x, p.y, p.z}, {0.f, 1.f, 0.f}, e);
    exact.push_back(SurfaceFitSample{p, {0.f, 1.f, 0.f}, luminance(e), 0.f});
  }
  DdgiResult kept = b.result;
  SurfaceFitReport report;
  ASSERT_TRUE(fit_irradiance_atlases(file, exact, SurfaceFitSettings{}, {&kept}, Context{}, report).is_ok());
  ASSERT_GT(report.texels, 0u);
  for (size_t i = 0; i < kept.irradiance_atlas.size(); ++i)
    ASSERT_NEAR(kept.irradiance_atlas[i], b.result.irradiance_atlas[i], 1e-3f * (1.f + b.result.irradiance_atlas[i]))
        << i;

  const std::vector<SurfaceFitSample> traced = traced_samples(b, floor_points(4, 1000), 64);
  DdgiResult one = b.result, two = b.result;
  Context single, pair;
  single.threads = 1;
  pair.threads = 2;
  ASSERT_TRUE(fit_irradiance_atlases(file, traced, SurfaceFitSettings{}, {&one}, single, report).is_ok());
  ASSERT_TRUE(fit_irradiance_atlases(file, traced, SurfaceFitSettings{}, {&two}, pair, report).is_ok());
  EXPECT_TRUE(one.irradiance_atlas == two.irradiance_atlas);
  EXPECT_FALSE(one.irradiance_atlas == b.result.irradiance_atlas) << "the fit changed nothing: the test shows nothing";
}

// The rows read only where the points are: rows built before the points' light is known (as a
// bake with a device builds them beside its paths) give the fit's bytes, and rows of other points
// are refused.
TEST(SurfaceFit, RowsBuiltBeforeTheLightGiveTheSameFit) {
  const Baked& b = baked();
  loader::BakeFile file;
  test::open_in_loader(b.result, file);
  const std::vector<SurfaceFitSample> traced = traced_samples(b, floor_points(4, 1000), 64);
  std::vector<SurfaceFitSample> unlit;
  for (const SurfaceFitSample& s : traced) unlit.push_back(SurfaceFitSample{s.p, s.n});
  DdgiResult whole = b.result, apart = b.result;
  SurfaceFitReport report;
  ASSERT_TRUE(fit_irradiance_atlases(file, traced, SurfaceFitSettings{}, {&whole}, Context{}, report).is_ok());
  const FitRows rows = fit_rows(file, unlit, {&apart}, Context{});
  ASSERT_EQ(rows.start.size(), traced.size() + 1);
  ASSERT_GT(rows.entries.size(), traced.size());
  ASSERT_TRUE(fit_irradiance_atlases(file, traced, rows, SurfaceFitSettings{}, {&apart}, Context{}, report).is_ok());
  EXPECT_TRUE(whole.irradiance_atlas == apart.irradiance_atlas);
  EXPECT_FALSE(whole.irradiance_atlas == b.result.irradiance_atlas)
      << "the fit changed nothing: the test shows nothing";

  const std::vector<SurfaceFitSample> fewer(traced.begin(), traced.begin() + 10);
  DdgiResult other = b.result;
  const Status refused = fit_irradiance_atlases(file, fewer, rows, SurfaceFitSettings{}, {&other}, Context{}, report);
  EXPECT_FALSE(refused.is_ok());
  EXPECT_TRUE(other.irradiance_atlas == b.result.irradiance_atlas);
}

}  // namespace
}  // namespace gibake
