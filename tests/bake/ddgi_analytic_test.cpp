// Bakes with analytic answers: white furnace, sunlit plane, emissive sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "kernels/octahedral.h"
#include "kernels/ray_gen.h"
#include "kernels/sh.h"
#include "tests/bake/scene_builders.h"
#include "tests/bake/test_backend.h"
#include "tests/support/probe_grid.h"

using namespace gibake;
using kernels::float3;

namespace {

DdgiSettings single_probe(const Vec3f& p, uint32_t rays) {
  DdgiSettings s = test::probe_grid(p, p, {1, 1, 1}, rays);
  s.relocate = false;
  s.seed = 1234;
  return s;
}

// A 4 km square ground plane at y = 0 facing +y, albedo rho: infinite as seen from a probe 1 m up.
void add_ground(Scene& scene, float rho) {
  const float half = 2000.f;
  test::add_quad(scene, {-half, 0, -half}, {half, 0, -half}, {half, 0, half}, {-half, 0, half}, {0, 1, 0},
                 test::add_material(scene, rho));
}

Status bake(const Scene& scene, const DdgiSettings& s, DdgiResult& r, DdgiReport& rep) {
  Context ctx;
  ctx.warn = [](const std::string& m) { std::fprintf(stderr, "warning: %s\n", m.c_str()); };
  return bake_ddgi(scene, test::on_test_backend(s), ctx, r, rep);
}

float3 sh_irr(const DdgiResult& r, int probe, const float3& n) {
  return kernels::sh_irradiance(&r.sh[size_t(probe) * r.desc.sh_coefficients() * 3], r.desc.sh_order, n);
}

// Interior texel (tx, ty) of probe `probe` in the irradiance atlas (red channel).
float atlas_texel(const DdgiResult& r, int probe, int tx, int ty) {
  kernels::AtlasLayout l;
  for (int a = 0; a < 3; ++a) l.counts[a] = r.desc.counts[a];
  l.res = kIrradianceTexels;
  l.planes_per_row = r.atlas_planes_per_row;
  int ox, oy;
  l.tile_origin(probe, ox, oy);
  return r.irradiance_atlas[(size_t(oy + 1 + ty) * r.irradiance_width + ox + 1 + tx) * 4];
}

}  // namespace

// Closed box, walls of albedo rho emitting Le, probe inside, probe-feedback gather: E(n) = pi Le
// sum_{k<=N} rho^k (emissive surfaces light others only through the probes, one pass each).
// The path gather's furnace is in path_gather_test.cpp.
TEST(DdgiAnalytic, WhiteFurnace) {
  Scene scene;
  const float rho = 0.5f, le = 2.f;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, rho, le));
  for (int bounces : {0, 1, 3}) {
    DdgiSettings s = single_probe({0.1f, -0.2f, 0.15f}, 4096);
    s.gather = Gather::Probes;
    s.bounces = bounces;
    DdgiResult r;
    DdgiReport rep;
    ASSERT_TRUE(bake(scene, s, r, rep)) << "bake failed";
    double geo = 0;
    for (int k = 0; k <= bounces; ++k) geo += std::pow(rho, k);
    const double expected = M_PI * le * geo;
    double worst_sh = 0, worst_atlas = 0;
    for (uint32_t i = 0; i < 64; ++i) {
      const float3 n = kernels::spherical_fibonacci(i, 64);
      worst_sh = std::max(worst_sh, std::fabs(sh_irr(r, 0, n).x / expected - 1.0));
    }
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) worst_atlas = std::max(worst_atlas, std::fabs(atlas_texel(r, 0, x, y) / expected - 1.0));
    std::printf("furnace N=%d expected %.5f lux: worst rel. error SH %.5f%%, atlas %.5f%%\n", bounces, expected,
                100 * worst_sh, 100 * worst_atlas);
    EXPECT_LT(worst_sh, 0.005);
    EXPECT_LT(worst_atlas, 0.005);
    EXPECT_EQ(r.states[0], ProbeState::Active);
  }
}

// Large plane of albedo rho under a sun of E0 lux, black sky, probe 1 m above:
// E(n) = rho E0 (1 - n.y) / 2 exactly (a hemisphere of uniform radiance rho E0 / pi below).
// SH: only bands 0 and 1 matter for this field (even bands >= 2 vanish for a half-space step,
// odd bands >= 3 have A_l = 0), so L1/L2 SH irradiance is exact up to sampling noise.
TEST(DdgiAnalytic, SunlitPlane) {
  Scene scene;
  const float rho = 0.6f, e0 = 1000.f;
  add_ground(scene, rho);
  DdgiSettings s = single_probe({0.f, 1.f, 0.f}, 8192);
  s.bounces = 2;
  s.suns.push_back(SunLight{{0.f, -1.f, 0.f}, e0, {1.f, 1.f, 1.f}});
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  const double ref = rho * e0;
  const float3 down{0, -1, 0}, side{1, 0, 0}, side2{0, 0, -1}, up{0, 1, 0};
  std::printf("sunlit plane SH: down %.3f (exp %.3f) side %.3f / %.3f (exp %.3f) up %.3f (exp 0)\n", sh_irr(r, 0, down).x,
              ref, sh_irr(r, 0, side).x, sh_irr(r, 0, side2).x, ref / 2, sh_irr(r, 0, up).x);
  EXPECT_NEAR(sh_irr(r, 0, down).x, ref, 0.005 * ref);
  EXPECT_NEAR(sh_irr(r, 0, side).x, ref / 2, 0.005 * ref);
  EXPECT_NEAR(sh_irr(r, 0, side2).x, ref / 2, 0.005 * ref);
  EXPECT_NEAR(sh_irr(r, 0, up).x, 0.0, 0.005 * ref);
  // Atlas: every texel against the analytic value at its own direction.
  double worst = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const float3 n = kernels::oct_texel_direction(x, y, 8);
      const double exact = ref * (1.0 - n.y) / 2.0;
      worst = std::max(worst, std::fabs(atlas_texel(r, 0, x, y) - exact) / ref);
    }
  std::printf("sunlit plane atlas: worst |texel - exact| / (rho E0) = %.5f%%\n", 100 * worst);
  EXPECT_LT(worst, 0.005);
}

// Emissive sphere of radius r, radiance L at distance d: irradiance facing it is pi L (r/d)^2.
TEST(DdgiAnalytic, EmissiveSphere) {
  Scene scene;
  const float radius = 1.f, dist = 2.f, lum = 100.f;
  test::add_sphere(scene, {0, 0, 0}, radius, 512, 256, test::add_material(scene, 0.f, lum));
  DdgiSettings s = single_probe({0.f, 0.f, dist}, 16384);
  s.bounces = 1;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  const float3 axis{0, 0, -1};
  const float cos_half = std::sqrt(1.f - (radius / dist) * (radius / dist));
  float exact[9];
  kernels::sh_project_uniform_cap(axis, cos_half, 2, exact);
  double worst = 0;
  for (int c = 0; c < 9; ++c) {
    const double err = std::fabs(r.sh[c * 3] - lum * exact[c]) / (lum * exact[0]);
    worst = std::max(worst, err);
    std::printf("sphere SH[%d] = %.5f exact %.5f\n", c, r.sh[c * 3], lum * exact[c]);
  }
  std::printf("sphere SH worst |error| / L00 = %.4f%%\n", 100 * worst);
  EXPECT_LT(worst, 0.01);

  // Atlas: for texels with the sphere entirely above their horizon (angle a <= 90 deg - half
  // angle) the exact irradiance is pi L (r/d)^2 cos a. Compare against the peak, 1% tolerance.
  const double peak = M_PI * lum * (radius / dist) * (radius / dist);
  double worst_texel = 0, best_dot = -1, facing_value = 0, facing_exact = 0;
  const float sin_half = radius / dist;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const float3 n = kernels::oct_texel_direction(x, y, 8);
      const float c = kernels::dot(n, axis);
      if (c < sin_half) continue;  // sphere partly below this texel's horizon
      const double ex = peak * c;
      worst_texel = std::max(worst_texel, std::fabs(atlas_texel(r, 0, x, y) - ex) / peak);
      if (c > best_dot) {
        best_dot = c;
        facing_value = atlas_texel(r, 0, x, y);
        facing_exact = ex;
      }
    }
  std::printf("sphere atlas: facing texel %.4f (exact %.4f at %.1f deg off-axis, peak %.4f); worst %.4f%%\n",
              facing_value, facing_exact, std::acos(best_dot) * 180 / M_PI, peak, 100 * worst_texel);
  EXPECT_NEAR(facing_value, facing_exact, 0.01 * peak);
  EXPECT_LT(worst_texel, 0.01);
}

// The same furnace seen by a 3x3x3 grid inside the box: bounces gather from up to 8 probes
// through the trilinear, back-face and Chebyshev weights (and extrapolate near the walls); every
// probe must still give the furnace value.
// (A grid straddling the walls would put probes 0.5 m outside the room that see its back faces
// on just under 25% of their rays: they stay active, see black, and leak darkness into the room
// through Chebyshev at oblique angles -- DDGI's usual thin-wall leak, see the report.)
TEST(DdgiAnalytic, WhiteFurnaceProbeGrid) {
  Scene scene;
  const float rho = 0.7f, le = 1.f;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, rho, le));
  DdgiSettings s = test::probe_grid({-0.7f, -0.7f, -0.7f}, {0.7f, 0.7f, 0.7f}, {3, 3, 3}, 2048);
  s.bounces = 3;
  s.gather = Gather::Probes;
  s.relocate = false;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  double geo = 0;
  for (int k = 0; k <= s.bounces; ++k) geo += std::pow(rho, k);
  const double expected = M_PI * le * geo;
  double worst = 0;
  for (int p = 0; p < 27; ++p) {
    EXPECT_EQ(r.states[p], ProbeState::Active) << p;
    for (uint32_t i = 0; i < 32; ++i)
      worst = std::max(worst, std::fabs(sh_irr(r, p, kernels::spherical_fibonacci(i, 32)).x / expected - 1.0));
    for (int ty = 0; ty < 8; ++ty)
      for (int tx = 0; tx < 8; ++tx) worst = std::max(worst, std::fabs(atlas_texel(r, p, tx, ty) / expected - 1.0));
  }
  std::printf("furnace grid: 27 probes, expected %.5f lux, worst rel. error %.4f%%\n", expected, 100 * worst);
  EXPECT_LT(worst, 0.005);
}

// A sunlit plane of albedo rho under a black, double-sided ceiling 3 m up whose material has
// `mode` and base-colour alpha `alpha` (MASK cutoff 0.5), baked for the probe 1 m above the plane
// with one bounce and a sun of e0 lux straight down. Returns E(down) at the probe.
static float plane_under_ceiling(AlphaMode mode, float alpha, float rho, float e0, DdgiSettings s, DdgiReport& rep) {
  Scene scene;
  const float half = 2000.f;
  add_ground(scene, rho);
  const int ceiling = test::add_material(scene, 0.f, 0.f, /*double_sided=*/true);
  scene.materials[ceiling].alpha_mode = mode;
  scene.materials[ceiling].alpha_cutoff = 0.5f;
  scene.materials[ceiling].base_color[3] = alpha;
  test::add_quad(scene, {-half, 3, -half}, {half, 3, -half}, {half, 3, half}, {-half, 3, half}, {0, -1, 0}, ceiling);
  s.bounces = 1;
  s.suns.push_back(SunLight{{0.f, -1.f, 0.f}, e0, {1.f, 1.f, 1.f}});
  DdgiResult r;
  EXPECT_TRUE(bake(scene, s, r, rep));
  return r.sh.empty() ? -1.f : sh_irr(r, 0, {0, -1, 0}).x;
}

// Alpha masking in both filters: alpha below the cutoff lets primary and shadow rays through, so
// the plane result is unchanged (rho E0); above it the ceiling blocks the sun and the view (0).
TEST(DdgiAnalytic, AlphaMaskedOccluder) {
  const float rho = 0.6f, e0 = 1000.f;
  for (float alpha : {0.2f, 0.8f}) {
    DdgiReport rep;
    const float down = plane_under_ceiling(AlphaMode::Mask, alpha, rho, e0, single_probe({0.f, 1.f, 0.f}, 4096), rep);
    EXPECT_EQ(rep.masked_triangles, 2u);
    std::printf("alpha %.1f: E(down) = %.3f\n", alpha, down);
    if (alpha < 0.5f) EXPECT_NEAR(down, rho * e0, 0.005 * rho * e0);
    else EXPECT_NEAR(down, 0.0, 1e-3);
  }
}

// BLEND is traced as MASK with --blend-cutoff (default 0.5; 0 = opaque): a BLEND ceiling of alpha
// 0.3 lets the sun through at the default cutoff (E(down) = rho E0) and blocks it at cutoff 0.2
// and 0 (E(down) = 0: nothing else lights the plane).
TEST(DdgiAnalytic, BlendCutoffOption) {
  const float rho = 0.6f, e0 = 1000.f;
  for (float cutoff : {0.5f, 0.2f, 0.f}) {
    DdgiSettings s = single_probe({0.f, 1.f, 0.f}, 4096);
    s.blend_cutoff = cutoff;
    DdgiReport rep;
    const float down = plane_under_ceiling(AlphaMode::Blend, 0.3f, rho, e0, s, rep);
    EXPECT_EQ(rep.masked_triangles, cutoff > 0.f ? 2u : 0u);
    std::printf("blend cutoff %.1f: E(down) = %.3f\n", cutoff, down);
    if (cutoff > 0.3f) EXPECT_NEAR(down, rho * e0, 0.005 * rho * e0);
    else EXPECT_NEAR(down, 0.0, 1e-3);
  }
  DdgiSettings s = single_probe({0.f, 1.f, 0.f}, 64);
  EXPECT_TRUE(validate_ddgi_settings(s));
  s.blend_cutoff = 1.5f;
  EXPECT_FALSE(validate_ddgi_settings(s));
}

// --light-sampling random picks one light per hit and scales it by the light count: two suns of
// E0/2 from the same direction then give exactly the one-sun answer, hit by hit.
TEST(DdgiAnalytic, RandomLightSamplingIsUnbiased) {
  Scene scene;
  const float rho = 0.6f, e0 = 1000.f;
  add_ground(scene, rho);
  DdgiSettings s = single_probe({0.f, 1.f, 0.f}, 2048);
  s.bounces = 1;
  s.light_sampling = LightSampling::Random;
  s.suns.push_back(SunLight{{0.f, -1.f, 0.f}, e0 / 2, {1.f, 1.f, 1.f}});
  s.suns.push_back(SunLight{{0.f, -1.f, 0.f}, e0 / 2, {1.f, 1.f, 1.f}});
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  EXPECT_NEAR(sh_irr(r, 0, {0, -1, 0}).x, rho * e0, 0.005 * rho * e0);
  EXPECT_LE(rep.shadow_rays, rep.primary_rays);  // one shadow ray per hit at most
}
