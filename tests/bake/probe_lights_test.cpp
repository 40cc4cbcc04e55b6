// The probe's own emitter samples, MIS-combined with its rays (bake/trace/path_gather.h), against
// answers known without our code: a probe under an emissive square in an otherwise black scene.
// The exact references: the solid angle of a centred rectangle, Omega = 4 asin(ab / sqrt((a^2 +
// 4h^2)(b^2 + 4h^2))), so L00 = Y00 Le Omega; and Lambert's polygon formula for the irradiance of a
// normal n that sees the whole square, E(n) = Le/2 sum_i angle(v_i, v_i+1) n.unit(v_i x v_i+1).
#include <OpenEXR/ImfRgbaFile.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <cstdio>
#include <vector>

#include <unistd.h>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/scene/emitters.h"
#include "bake/scene/prepare.h"
#include "bake/scene/sky.h"
#include "bake/trace/path_gather.h"
#include "kernels/octahedral.h"
#include "kernels/ray_gen.h"
#include "tests/bake/scene_builders.h"
#include "tests/bake/test_backend.h"
#include "tests/support/probe_grid.h"
#include "tests/support/scratch_dir.h"

using namespace gibake;

namespace {

constexpr double kY00 = 0.28209479177387814;
constexpr float kLe = 50.f;

// A black scene with one single-sided Le square of side `a` centred `h` above the origin, facing
// down, albedo 0 (nothing reflects).
Scene lamp_scene(float a, float h) {
  Scene s;
  const int lamp = test::add_material(s, 0.f, kLe);
  const float r = a / 2;
  test::add_quad(s, {-r, h, -r}, {r, h, -r}, {r, h, r}, {-r, h, r}, {0, -1, 0}, lamp);
  return s;
}

double solid_angle(double a, double h) { return 4.0 * std::asin(a * a / ((a * a + 4 * h * h))); }

// The grid of the bake tests: one probe at the origin, not relocated, lit directly only.
DdgiSettings lone_probe(uint32_t rays) {
  DdgiSettings s = test::probe_grid({0, 0, 0}, {0, 0, 0}, {1, 1, 1}, rays);
  s.relocate = false;
  s.bounces = 0;
  return s;
}

// Lambert's formula for the square seen from the origin with normal n; < 0 when n does not see
// all of it (no closed form used then).
double polygon_irradiance(double a, double h, const kernels::float3& n) {
  const double r = a / 2, c[4][3] = {{-r, h, -r}, {r, h, -r}, {r, h, r}, {-r, h, r}};
  double sum = 0;
  for (int i = 0; i < 4; ++i) {
    const double* p = c[i];
    const double* q = c[(i + 1) % 4];
    if (p[0] * n.x + p[1] * n.y + p[2] * n.z <= 0) return -1;
    const double lp = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), lq = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    const double angle = std::acos((p[0] * q[0] + p[1] * q[1] + p[2] * q[2]) / (lp * lq));
    const double x[3] = {p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]};
    const double lx = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    sum += angle * (x[0] * n.x + x[1] * n.y + x[2] * n.z) / lx;
  }
  return std::fabs(sum) * kLe / 2;
}

// One probe's L00 from `rays` rays at the origin (seed, pass 0), with or without the probe's
// emitter samples: the trace and the integrator the bake runs.
double probe_l00(const PathSetup& ps, uint32_t rays, uint64_t seed, bool probe_lights) {
  std::vector<float> dirs(size_t(rays) * 3);
  kernels::generate_probe_rays(seed, 0, 0, rays, dirs.data());
  std::vector<kernels::HitRecord> h(rays);
  std::vector<kernels::RaySample> s(size_t(rays) * 2);
  PathSetup setup = ps;
  setup.trace.seed = seed;
  TraceCounters tc;
  trace_probe_paths(setup, {0, 0, 0}, 0, 0, dirs.data(), rays, h.data(), tc, nullptr,
                    probe_lights ? s.data() + rays : nullptr);
  for (uint32_t r = 0; r < rays; ++r)
    s[r] = {{h[r].dir_t[0], h[r].dir_t[1], h[r].dir_t[2], 1.f}, {h[r].radiance0[0], h[r].radiance0[1], h[r].radiance0[2], 0.f}};
  const std::vector<float> texels = kernels::oct_tile_directions(8);
  float sh[27];
  kernels::integrate_radiance(texels.data(), 8, s.data(), int(probe_lights ? 2 * rays : rays), 2, sh, nullptr,
                              int(rays));
  return sh[0];
}

// A sky with a small sun: radiance 1000 where |u - 0.3| < 0.02 and |v - 0.3| < 0.04, 0.1
// elsewhere, sampled at texel centres of a 128 x 64 map.
constexpr int kSkyW = 128, kSkyH = 64;
float sun_sky(float u, float v) { return std::fabs(u - 0.3f) < 0.02f && std::fabs(v - 0.3f) < 0.04f ? 1000.f : 0.1f; }

// Its integral over the sphere, texel by texel: value x the solid angle of its cell (the
// bilinear lookup's hat functions integrate to the cells' up to O(1/H^2) in sin(theta): 0.1%).
double sun_sky_integral() {
  double sum = 0;
  for (int y = 0; y < kSkyH; ++y)
    for (int x = 0; x < kSkyW; ++x)
      sum += sun_sky((x + 0.5f) / kSkyW, (y + 0.5f) / kSkyH) * (2 * M_PI / kSkyW) *
             (std::cos(M_PI * y / kSkyH) - std::cos(M_PI * (y + 1) / kSkyH));
  return sum;
}

std::string write_sun_exr(const std::string& name) {
  const std::string path = (gibake::test::process_tmp() / name).string();
  std::vector<Imf::Rgba> px(size_t(kSkyW) * kSkyH);
  for (int y = 0; y < kSkyH; ++y)
    for (int x = 0; x < kSkyW; ++x) {
      const float v = sun_sky((x + 0.5f) / kSkyW, (y + 0.5f) / kSkyH);
      px[size_t(y) * kSkyW + x] = Imf::Rgba(v, v, v, 1.f);
    }
  Imf::RgbaOutputFile file(path.c_str(), kSkyW, kSkyH, Imf::WRITE_RGBA);
  file.setFrameBuffer(px.data(), 1, kSkyW);
  file.writePixels(kSkyH);
  return path;
}

// `n` probes at the origin, one bake: each probe draws its own random stream (the rays' and the
// light samples' keys hold the probe's index beside the seed), so their L00s are n independent
// estimates, as n one-probe bakes with n seeds are, for the set-up cost of one bake.
DdgiSettings probes_at_origin(int n, uint32_t rays) {
  DdgiSettings s = test::probe_grid({0, 0, 0}, {0, 0, 0}, {n, 1, 1}, rays);
  s.relocate = false;
  s.seed = 1;
  return s;
}

double baked_l00(const DdgiResult& r, int probe) { return r.sh[size_t(probe) * r.desc.sh_coefficients() * 3]; }

struct Spread {
  double mean = 0, sd = 0;
};

// Mean and spread of the L00s of the probes of one bake (probes_at_origin).
Spread baked_spread(const DdgiResult& r) {
  double sum = 0, sum2 = 0;
  const int n = r.desc.probe_count();
  for (int p = 0; p < n; ++p) {
    sum += baked_l00(r, p);
    sum2 += baked_l00(r, p) * baked_l00(r, p);
  }
  Spread s;
  s.mean = sum / n;
  s.sd = std::sqrt(std::max(0.0, sum2 / n - s.mean * s.mean));
  return s;
}

Spread spread(const PathSetup& ps, uint32_t rays, int seeds, bool probe_lights) {
  double sum = 0, sum2 = 0;
  for (int k = 1; k <= seeds; ++k) {
    const double v = probe_l00(ps, rays, uint64_t(k), probe_lights);
    sum += v;
    sum2 += v * v;
  }
  Spread s;
  s.mean = sum / seeds;
  s.sd = std::sqrt(std::max(0.0, sum2 / seeds - s.mean * s.mean));
  return s;
}

}  // namespace

// The estimator itself, rays alone and rays + emitter samples (MIS) over 64 seeds at
// 64 rays: a 0.2 m lamp 1 m up (the cornell-box-nvpro case: 1 in 300 rays hits it) and a 4 m one
// 0.5 m up (most rays hit it: the rays' weight matters). Both must be unbiased (mean within 4
// standard errors, and within 1% with MIS); the MIS spread must be at least 10x smaller
// on the small lamp and no worse on the big one.
TEST(ProbeLights, MisLowersSpreadWithoutBias) {
  struct Case {
    float a, h;
    double min_factor;
  };
  for (const Case c : {Case{0.2f, 1.f, 10.0}, Case{4.f, 0.5f, 1.0}}) {
    const Scene scene = lamp_scene(c.a, c.h);
    std::unique_ptr<PreparedScene> prepared;
    ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
    const EmitterTable emitters(scene);
    const Sky sky;
    const std::vector<kernels::ShadeLight> lights;
    const PathSetup ps = make_path_setup(*prepared, lights, sky, emitters, 1, 0);
    const double exact = kY00 * kLe * solid_angle(c.a, c.h);
    const int seeds = 64;
    const Spread old_s = spread(ps, 64, seeds, false), new_s = spread(ps, 64, seeds, true);
    std::printf("lamp %.1f m at %.1f m, 64 rays, %d seeds: exact L00 %.5f; rays alone mean %.5f sd %.2f%%; "
                "with emitter samples mean %.5f sd %.3f%%; spread %.1fx smaller\n",
                c.a, c.h, seeds, exact, old_s.mean, 100 * old_s.sd / exact, new_s.mean, 100 * new_s.sd / exact,
                old_s.sd / new_s.sd);
    EXPECT_NEAR(old_s.mean, exact, 4 * old_s.sd / std::sqrt(seeds) + 1e-3 * exact);
    EXPECT_NEAR(new_s.mean, exact, 0.01 * exact);
    EXPECT_GE(old_s.sd / new_s.sd, c.min_factor);
  }
}

// The bake (CPU, or Vulkan on lavapipe in the twin test): a 0.3 m lamp 1 m above one probe. At
// 1,024 rays every irradiance texel that sees the whole lamp is within 1.5% of Lambert's formula
// and L00 within 1% of the solid angle's; at 64 rays, L00 over 16 independent estimates (16 probes
// at the same point) spreads less than 3% (the rays alone: about 150%, see above).
TEST(ProbeLights, BakeMatchesFormFactor) {
  const float a = 0.3f, h = 1.f;
  const Scene scene = lamp_scene(a, h);
  const double exact = kY00 * kLe * solid_angle(a, h);
  DdgiSettings s = lone_probe(1024);
  Context ctx;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, test::on_test_backend(s), ctx, r, rep));
  EXPECT_NEAR(r.sh[0], exact, 0.01 * exact);
  double worst = 0;
  int checked = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const kernels::float3 n = kernels::oct_texel_direction(x, y, 8);
      const double e = polygon_irradiance(a, h, n);
      if (e <= 0) continue;
      const float got = r.irradiance_atlas[(size_t(1 + y) * r.irradiance_width + 1 + x) * 4];
      worst = std::max(worst, std::fabs(got / e - 1));
      ++checked;
    }
  std::printf("lamp %.1f m at %.1f m, 1024 rays: L00 %.5f (exact %.5f), %d texels, worst %.3f%%\n", a, h, r.sh[0],
              exact, checked, 100 * worst);
  EXPECT_GE(checked, 8);
  EXPECT_LT(worst, 0.015);
  const int seeds = 16;
  DdgiSettings s64 = probes_at_origin(seeds, 64);
  s64.bounces = 0;
  DdgiResult r64;
  ASSERT_TRUE(bake_ddgi(scene, test::on_test_backend(s64), ctx, r64, rep));
  double reported = 0;
  for (int p = 0; p < seeds; ++p) reported += r64.stats[size_t(p)].relative_error;
  const Spread sp = baked_spread(r64);
  const double mean = sp.mean, sd = sp.sd;
  std::printf("64 rays over %d probes: L00 mean %.5f, sd %.3f%% of exact; reported relative error %.3f%%\n", seeds,
              mean, 100 * sd / exact, 100 * reported / seeds);
  EXPECT_LT(sd, 0.03 * exact);
  EXPECT_NEAR(mean, exact, 0.02 * exact);
  // --target-error's statistic is that of the combined estimator: it never claims less than the
  // spread measured over seeds (it treats the stratified samples as independent, so it may claim
  // more), and it is that of the pairs, far below the rays' alone (about 150% here).
  EXPECT_GT(reported / seeds, 0.5 * sd / mean);
  EXPECT_LT(reported / seeds, 0.01);
}

// Adaptive rays keep every batch's emitter samples with its records: 64 rays a batch until the
// relative error is below 0.1% (3 batches at the spread measured above), the result as exact.
TEST(ProbeLights, AdaptiveBatchesKeepTheirEmitterSamples) {
  const float a = 0.3f, h = 1.f;
  const Scene scene = lamp_scene(a, h);
  const double exact = kY00 * kLe * solid_angle(a, h);
  DdgiSettings s = lone_probe(64);
  s.target_error = 0.001f;
  s.max_rays = 1024;
  Context ctx;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, test::on_test_backend(s), ctx, r, rep));
  std::printf("adaptive: %u rays, reported relative error %.4f%%, L00 %.5f (exact %.5f)\n", r.stats[0].rays,
              100 * r.stats[0].relative_error, r.sh[0], exact);
  EXPECT_GE(r.stats[0].rays, 128u);
  EXPECT_LT(r.stats[0].rays, 1024u);
  EXPECT_LT(r.stats[0].relative_error, 0.001f);
  EXPECT_NEAR(r.sh[0], exact, 0.005 * exact);
}

// The emitter samples cast shadow rays: a black half-plane halfway up hides the lamp's x < 0 half
// from the probe, so L00 is exactly half the unblocked value (the solid angle splits evenly). The
// edge cuts the lamp's triangles, so one probe's stratified samples miss it by up to ~2% at 256
// rays (within 4% each): the mean of 32 independent estimates (32 probes at the same point) must be
// within 0.5%.
TEST(ProbeLights, BlockedHalfOfTheLampIsNotSeen) {
  const float a = 0.3f, h = 1.f;
  Scene scene = lamp_scene(a, h);
  test::add_quad(scene, {-5, 0.5f, -5}, {0, 0.5f, -5}, {0, 0.5f, 5}, {-5, 0.5f, 5}, {0, -1, 0}, test::add_material(scene, 0.f));
  const double exact = kY00 * kLe * solid_angle(a, h) / 2;
  double sum = 0;
  const int seeds = 32;
  DdgiSettings s = probes_at_origin(seeds, 256);
  s.bounces = 0;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, test::on_test_backend(s), Context{}, r, rep));
  for (int p = 0; p < seeds; ++p) {
    EXPECT_NEAR(baked_l00(r, p), exact, 0.04 * exact) << "probe " << p;
    sum += baked_l00(r, p);
  }
  std::printf("half-blocked lamp, 256 rays: L00 mean of %d probes %.5f (exact %.5f)\n", seeds, sum / seeds, exact);
  EXPECT_NEAR(sum / seeds, exact, 0.005 * exact);
}

// The sky map sampled from the probe: an empty scene under the sun sky. At the trace level (64
// rays, 64 seeds), rays alone vs rays + light samples (MIS): both unbiased, the spread at least
// 10x smaller. Then the bake (CPU, or lavapipe in the twin test), 256 rays, 16 independent
// estimates (16 probes at the same point): L00 within 1% of the texel sum, spread under 2%.
TEST(ProbeLights, SkyMapSampledFromTheProbe) {
  const double exact = kY00 * sun_sky_integral();
  {
    const Scene scene;
    std::unique_ptr<PreparedScene> prepared;
    ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
    const EmitterTable emitters(scene);
    Sky sky;
    sky.width = kSkyW;
    sky.height = kSkyH;
    sky.rgb.resize(size_t(kSkyW) * kSkyH * 3);
    for (int y = 0; y < kSkyH; ++y)
      for (int x = 0; x < kSkyW; ++x)
        for (int c = 0; c < 3; ++c)
          sky.rgb[(size_t(y) * kSkyW + x) * 3 + c] = sun_sky((x + 0.5f) / kSkyW, (y + 0.5f) / kSkyH);
    build_sky_sampling(sky);
    ASSERT_TRUE(sky.sampled());
    const std::vector<kernels::ShadeLight> lights;
    const PathSetup ps = make_path_setup(*prepared, lights, sky, emitters, 1, 0);
    const int seeds = 64;
    const Spread old_s = spread(ps, 64, seeds, false), new_s = spread(ps, 64, seeds, true);
    std::printf("sun sky, 64 rays, %d seeds: exact L00 %.4f; rays alone mean %.4f sd %.1f%%; with sky samples mean "
                "%.4f sd %.3f%%; spread %.1fx smaller\n",
                seeds, exact, old_s.mean, 100 * old_s.sd / exact, new_s.mean, 100 * new_s.sd / exact,
                old_s.sd / new_s.sd);
    EXPECT_NEAR(old_s.mean, exact, 4 * old_s.sd / std::sqrt(seeds) + 2e-3 * exact);
    EXPECT_NEAR(new_s.mean, exact, 0.01 * exact);
    EXPECT_GE(old_s.sd / new_s.sd, 10.0);
  }
  // One file a process: the CPU suite and its lavapipe twin run side by side under ctest.
  const std::string path = write_sun_exr("gibake_probe_lights_sun.exr");
  const int seeds = 16;
  DdgiSettings s = probes_at_origin(seeds, 256);
  s.sky_hdr = path;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(Scene{}, test::on_test_backend(s), Context{}, r, rep));
  const Spread sky_spread = baked_spread(r);
  const double mean = sky_spread.mean, sd = sky_spread.sd;
  std::printf("sun sky bake, 256 rays over %d probes: L00 mean %.4f (exact %.4f), sd %.3f%%\n", seeds, mean, exact,
              100 * sd / exact);
  EXPECT_NEAR(mean, exact, 0.01 * exact);
  EXPECT_LT(sd, 0.02 * exact);
  // Both at once (half the light samples each): the 0.3 m lamp 1 m up under the sun sky, which it
  // hides where it stands (radiance 0.1 there): Y00 (Le Omega + sky integral - 0.1 Omega).
  const double omega = solid_angle(0.3, 1.0), both = kY00 * (kLe * omega + sun_sky_integral() - 0.1 * omega);
  s.bounces = 0;
  DdgiResult r2;
  ASSERT_TRUE(bake_ddgi(lamp_scene(0.3f, 1.f), test::on_test_backend(s), Context{}, r2, rep));
  const Spread both_spread = baked_spread(r2);
  const double mean2 = both_spread.mean, sd2 = both_spread.sd;
  std::printf("lamp under the sun sky, 256 rays over %d probes: L00 mean %.4f (exact %.4f), sd %.3f%%\n", seeds,
              mean2, both, 100 * sd2 / both);
  EXPECT_NEAR(mean2, both, 0.01 * both);
  EXPECT_LT(sd2, 0.02 * both);
  std::filesystem::remove(path);
}
