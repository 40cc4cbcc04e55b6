// Where a probe's irradiance comes from, judged by light whose answer is known without the bake: a
// bright strip on the ground facing up, in a black world (no sky, nothing else), and points just
// above the ground beside it, where the strip lies a few degrees below their horizon. A surface
// there facing up sees only the black world: its irradiance is exactly 0. One facing down sees the
// strip: E = L x (its cosine-weighted solid angle), the closed form of rectangles seen from above a
// corner. The loader reads a probe's irradiance from its irradiance atlas (each texel the
// cosine-weighted mean of the probe's rays around its direction), which follows both to within its
// texels' spread; a probe's two-band SH cannot tell "just below the horizon" from "just above" and
// ring: the up-facing surface reads most of what a surface facing the strip gets. In a sunlit scene the same error
// lights a shaded floor with the sunlit floor beyond it (docs/BENCHMARKS.md "The irradiance atlas").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "gibake/loader.hpp"
#include "tests/bake/loader_file.h"
#include "tests/bake/scene_builders.h"

namespace gibake {
namespace {

constexpr float kRadiance = 20.f;                            // cd/m^2, the strip's
constexpr float kNear = 2.f, kFar = 10.f, kHalfWidth = 4.f;  // the strip: x in [2, 10] m, z in [-4, 4] m
constexpr float kHeight = 0.3f;                              // the points' height above the ground, m

// Cosine-weighted solid angle of the rectangle [0, a] x [0, b] seen by a surface facing it from a
// height h above its corner (pi times the form factor).
double corner_view(double a, double b, double h) {
  const double x = a / h, y = b / h;
  const double sx = std::sqrt(1.0 + x * x), sy = std::sqrt(1.0 + y * y);
  return 0.5 * (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy));
}

// Irradiance (lux) at the points (x = 0, z = 0, kHeight) facing down: the strip as the difference
// of two rectangles from below the point, two quarters each.
double facing_down() {
  return kRadiance * 2.0 * (corner_view(kFar, kHalfWidth, kHeight) - corner_view(kNear, kHalfWidth, kHeight));
}

float luminance(const loader::Rgb& e) { return 0.2126f * e[0] + 0.7152f * e[1] + 0.0722f * e[2]; }

TEST(HorizonLight, ASurfaceFacingAwayFromABrightSourceBelowItsHorizonReadsLittleOfIt) {
  Scene scene;
  test::add_quad(scene, {kNear, 0.f, -kHalfWidth}, {kNear, 0.f, kHalfWidth}, {kFar, 0.f, kHalfWidth},
                 {kFar, 0.f, -kHalfWidth}, {0, 1, 0}, test::add_material(scene, 0.f, kRadiance));
  DdgiSettings s;
  s.rays = 4096;
  s.target_error = 0.f;
  s.bounces = 1;
  s.cgal_check = false;
  s.relocate = false;
  s.grid.explicit_bounds = true;  // probes 0.15 m apart around the point, none on the ground
  s.grid.grid_min = {-0.15f, 0.15f, -0.15f};
  s.grid.grid_max = {0.15f, 0.45f, 0.15f};
  s.grid.counts = {3, 3, 3};
  DdgiResult result;
  DdgiReport report;
  ASSERT_TRUE(bake_ddgi(scene, s, Context{}, result, report).is_ok());
  loader::BakeFile file;
  test::open_in_loader(result, file);
  ASSERT_FALSE(file.ddgi_volumes().empty());
  ASSERT_TRUE(file.ddgi_volumes()[0].has_irradiance());
  loader::SampleOptions sh;
  sh.use_irradiance_atlas = false;
  const loader::Vec3 p{0.f, kHeight, 0.f};
  loader::Rgb up{}, down{}, up_sh{}, down_sh{};
  ASSERT_TRUE(file.sample_ddgi(p, {0.f, 1.f, 0.f}, up));
  ASSERT_TRUE(file.sample_ddgi(p, {0.f, -1.f, 0.f}, down));
  ASSERT_TRUE(file.sample_ddgi(p, {0.f, 1.f, 0.f}, up_sh, sh));
  ASSERT_TRUE(file.sample_ddgi(p, {0.f, -1.f, 0.f}, down_sh, sh));
  const double truth = facing_down();
  std::printf("facing down %.3f lux (truth %.3f; from the SH %.3f), facing up %.4f lux (truth 0; from the SH %.3f)\n",
              luminance(down), truth, luminance(down_sh), luminance(up), luminance(up_sh));
  // Facing down: the probes' blend of the strip's view. The strip lies 2 to 9 degrees below the
  // point's horizon, so its view grows fast with height, and the probes 0.15 m above the point see
  // more of it than those below see less: within 30%.
  EXPECT_NEAR(luminance(down), truth, 0.3 * truth);
  // Facing up: the atlas's texels nearest the normal look a few degrees aside, so the bilinear read
  // takes a little of the strip; the SH read far more of it, most of what a surface facing the
  // strip gets.
  EXPECT_LT(luminance(up), 0.3 * truth);
  EXPECT_LT(luminance(up), 0.5 * luminance(up_sh));
  EXPECT_GT(luminance(up_sh), 0.5 * truth);
}

}  // namespace
}  // namespace gibake
