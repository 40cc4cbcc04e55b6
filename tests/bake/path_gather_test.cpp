// The path-traced gather against answers known without our code: furnaces (geometric sums), a
// sealed dark room beside a lit one (exactly 0), probes inside a bottomless box on a floor
// (inactive), probes that see only sky, thread-count determinism and adaptive rays; a surface
// point's paths with their emitter samples against the irradiance of a small lamp above it.
#include "bake/trace/path_gather.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/scene/emitters.h"
#include "bake/scene/lights.h"
#include "bake/scene/prepare.h"
#include "bake/scene/sky.h"
#include "kernels/path.h"
#include "kernels/ray_gen.h"
#include "kernels/sh.h"
#include "tests/bake/scene_builders.h"
#include "tests/bake/test_backend.h"
#include "tests/support/probe_grid.h"

using namespace gibake;
using kernels::float3;

namespace {

DdgiSettings probes_at(const Vec3f& lo, const Vec3f& hi, std::array<int32_t, 3> counts, uint32_t rays) {
  DdgiSettings s = test::probe_grid(lo, hi, counts, rays);
  s.relocate = false;
  s.seed = 99;
  return s;
}

// The first states.size() probes' states, probe by probe.
void expect_states(const DdgiResult& r, const std::vector<ProbeState>& states) {
  for (size_t i = 0; i < states.size(); ++i) EXPECT_EQ(r.states[i], states[i]) << "probe " << i;
}

Status bake(const Scene& scene, const DdgiSettings& s, DdgiResult& r, DdgiReport& rep, unsigned threads = 0) {
  Context ctx;
  ctx.threads = threads;
  return bake_ddgi(scene, test::on_test_backend(s), ctx, r, rep);
}

float3 sh_irr(const DdgiResult& r, int probe, const float3& n) {
  return kernels::sh_irradiance(&r.sh[size_t(probe) * r.desc.sh_coefficients() * 3], r.desc.sh_order, n);
}

// Worst relative error of E(n) over 64 directions against a constant.
double worst_error(const DdgiResult& r, int probe, double expected) {
  double worst = 0;
  for (uint32_t i = 0; i < 64; ++i)
    worst = std::max(worst, std::fabs(sh_irr(r, probe, kernels::spherical_fibonacci(i, 64)).x / expected - 1.0));
  return worst;
}

}  // namespace

// Closed box whose walls have albedo rho and emit Le; a probe inside. A path that reflects N more
// times after its first hit and samples the emitting walls at every vertex gathers
// E = pi Le sum_{k=0}^{N+1} rho^k; with Russian roulette and many bounces, pi Le / (1 - rho).
// Emission is met by bounce rays and by light sampling alike, so double counting would show here.
// 16384 rays; tolerance 2% on the worst of 64 directions (the rho = 0.8 limit, the noisiest case,
// has a seed-to-seed spread of about 1.4% at 8192 rays on the mean; bias is tested over seeds below).
// The furnace limit pi Le / (1 - rho) at rho = 0.8 (long paths, Russian roulette doing most of
// the stopping): one probe's estimate has about 1.4% noise at 8192 rays. Inside a furnace every
// point sees the same irradiance, so 64 probes of one bake are 64 independent estimates (each probe
// draws its own random stream): their mean (0.18% standard error) must land within 0.5% -- a bias
// test for roulette and MIS together.
TEST(PathGather, FurnaceLimitIsUnbiasedOverSeeds) {
  Scene scene;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, 0.8f, 2.f));
  const double expected = M_PI * 2.0 / (1.0 - 0.8);
  DdgiSettings s = probes_at({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f}, {4, 4, 4}, 8192);
  s.bounces = 64;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  const int probes = 64;
  double sum = 0, sum_sq = 0;
  for (int p = 0; p < probes; ++p) {
    ASSERT_EQ(r.states[p], ProbeState::Active) << "probe " << p;
    const double e = M_PI * r.sh[size_t(p) * r.desc.sh_coefficients() * 3] / std::sqrt(4 * M_PI);  // from L00
    sum += e;
    sum_sq += e * e;
  }
  const double mean = sum / probes, spread = std::sqrt(std::max(0.0, sum_sq / probes - mean * mean));
  std::printf("furnace limit over %d probes: mean E %.4f lux (probe spread %.2f%%), expected %.4f\n", probes, mean,
              100 * spread / mean, expected);
  EXPECT_NEAR(mean, expected, 0.005 * expected);
  // Independent estimates: the probes must differ by about one probe's noise, not agree exactly.
  EXPECT_GT(spread / mean, 0.002);
}

TEST(PathGather, WhiteFurnace) {
  for (float rho : {0.3f, 0.5f, 0.8f}) {
    Scene scene;
    const float le = 2.f;
    test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, rho, le));
    for (int bounces : {0, 2, 64}) {
      DdgiSettings s = probes_at({0.1f, -0.2f, 0.15f}, {0.1f, -0.2f, 0.15f}, {1, 1, 1}, 16384);
      s.bounces = bounces;
      DdgiResult r;
      DdgiReport rep;
      ASSERT_TRUE(bake(scene, s, r, rep));
      double geo = 0;
      for (int k = 0; k <= bounces + 1; ++k) geo += std::pow(rho, k);
      if (bounces == 64) geo = 1.0 / (1.0 - rho);
      const double expected = M_PI * le * geo, worst = worst_error(r, 0, expected);
      std::printf("path furnace rho %.1f N=%d: expected %.4f lux, E(+x) %.4f, worst rel. error %.3f%%\n", rho,
                  bounces, expected, sh_irr(r, 0, {1, 0, 0}).x, 100 * worst);
      EXPECT_LT(worst, 0.015) << "rho " << rho << " bounces " << bounces;
      EXPECT_EQ(r.states[0], ProbeState::Active);
    }
  }
}

// Two rooms sharing a 0.2 m wall: room A has an emissive ceiling patch, room B is sealed and has
// no light. No path from B's probes can reach light: they read exactly 0 and are inactive
// (enclosed, unlit); A's probes are lit and active.
TEST(PathGather, SealedDarkRoomBesideLitRoomReadsZero) {
  Scene scene;
  const int wall = test::add_material(scene, 0.7f);
  test::add_box(scene, {0, 0, 0}, {2, 2, 2}, /*inward=*/true, wall);
  test::add_box(scene, {2.2f, 0, 0}, {4.2f, 2, 2}, /*inward=*/true, wall);
  test::add_quad(scene, {0.7f, 1.99f, 0.7f}, {1.3f, 1.99f, 0.7f}, {1.3f, 1.99f, 1.3f}, {0.7f, 1.99f, 1.3f}, {0, -1, 0},
                 test::add_material(scene, 0.f, 50.f));
  DdgiSettings s = probes_at({0.5f, 0.5f, 0.5f}, {3.7f, 1.5f, 1.5f}, {5, 2, 2}, 512);
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  const int coefs = r.desc.sh_coefficients();
  for (int p = 0; p < r.desc.probe_count(); ++p) {
    const float x = r.desc.grid_min[0] + r.desc.spacing[0] * float(p % 5);
    if (x > 2.2f) {
      for (int c = 0; c < coefs * 3; ++c) EXPECT_EQ(r.sh[size_t(p) * coefs * 3 + c], 0.f) << "probe " << p;
      EXPECT_EQ(r.states[p], ProbeState::Inactive) << "probe " << p;
    } else if (x < 2.f) {
      EXPECT_GT(sh_irr(r, p, {0, 1, 0}).x, 1.f) << "probe " << p;
      EXPECT_EQ(r.states[p], ProbeState::Active) << "probe " << p;
    }
  }
  EXPECT_EQ(rep.enclosed, 8);  // x = 2.9 and 3.7; the probes at x = 2.1 sit inside the wall (back faces)
}

// A double-sided box without a bottom face standing on a lit floor (a glTF export's usual
// block): closed only together with the floor. Probes inside it see no light and are inactive;
// the probes around it stay active.
TEST(PathGather, ProbesInsideBottomlessBoxOnFloorAreInactive) {
  Scene scene;
  test::add_quad(scene, {-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}, {0, 1, 0}, test::add_material(scene, 0.6f, 0.f, true));
  test::add_box(scene, {-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f}, /*inward=*/false, test::add_material(scene, 0.5f, 0.f, true),
                test::kSkipBottom);
  DdgiSettings s = probes_at({-1.5f, 0.5f, 0.f}, {1.5f, 0.5f, 0.f}, {3, 1, 1}, 256);  // outside, inside, outside
  s.suns.push_back(SunLight{{0.3f, -1.f, 0.2f}, 1000.f, {1, 1, 1}});
  s.sky = {0.5f, 0.5f, 0.5f};
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  expect_states(r, {ProbeState::Active, ProbeState::Inactive, ProbeState::Active});
  EXPECT_EQ(r.stats[1].backface_fraction, 0.f);  // double-sided: the back-face test cannot tell
  EXPECT_EQ(rep.enclosed, 1);
}

// A probe whose rays meet no geometry holds the sky and is marked sky-only.
TEST(PathGather, ProbeThatSeesOnlySkyIsMarked) {
  Scene scene;
  test::add_quad(scene, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 0}, test::add_material(scene, 0.5f));
  DdgiSettings s = probes_at({0, 0.5f, 0}, {0, 500.5f, 0}, {1, 2, 1}, 256);  // above the quad; far above it
  s.sky = {2.f, 2.f, 2.f};
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  expect_states(r, {ProbeState::Active, ProbeState::SkyOnly});
  EXPECT_NEAR(sh_irr(r, 1, {0, 1, 0}).x, M_PI * 2.0, 1e-3);  // uniform sky: E = pi L
  EXPECT_EQ(rep.sky_only, 1);
}

// A closed room lit by a small ceiling lamp, 3 x 2 x 3 probes at 64 rays a batch, adaptive to 3%
// (up to 1024 rays): the lamp's noise makes some probes need several batches.
Scene lamp_room(DdgiSettings& s) {
  Scene scene;
  test::add_box(scene, {0, 0, 0}, {3, 2, 3}, /*inward=*/true, test::add_material(scene, 0.6f));
  test::add_quad(scene, {1.2f, 1.99f, 1.2f}, {1.8f, 1.99f, 1.2f}, {1.8f, 1.99f, 1.8f}, {1.2f, 1.99f, 1.8f}, {0, -1, 0},
                 test::add_material(scene, 0.f, 40.f));
  s = probes_at({0.5f, 0.5f, 0.5f}, {2.5f, 1.5f, 2.5f}, {3, 2, 3}, 64);
  s.target_error = 0.03f;
  s.max_rays = 1024;
  return scene;
}

// Bakes on 1 and on 2 threads into `a` (and its report `ra`), expecting the same bytes from both.
void bake_on_one_and_two_threads(const Scene& scene, const DdgiSettings& s, DdgiResult& a, DdgiReport& ra) {
  DdgiResult b;
  DdgiReport rb;
  ASSERT_TRUE(bake(scene, s, a, ra, 1));
  ASSERT_TRUE(bake(scene, s, b, rb, 2));
  EXPECT_EQ(a.sh, b.sh);
  EXPECT_EQ(a.irradiance_atlas, b.irradiance_atlas);
  EXPECT_EQ(a.depth_atlas, b.depth_atlas);
}

// The budget is held per block of 512 probes (io/results/ddgi_shard.h), so that shards decide as the
// one-go bake: 768 probes (blocks of 512 and 256), each block within its share whatever the thread
// count, though without the budget each would spend more.
TEST(PathGather, RayBudgetHoldsPerBlockOfProbes) {
  DdgiSettings s;
  const Scene scene = lamp_room(s);
  s.grid.counts = {12, 8, 8};
  DdgiResult unbounded, a, b;
  DdgiReport ru, ra, rb;
  ASSERT_TRUE(bake(scene, s, unbounded, ru, 2));
  s.ray_budget = 96;
  ASSERT_TRUE(bake(scene, s, a, ra, 1));
  ASSERT_TRUE(bake(scene, s, b, rb, 2));
  EXPECT_EQ(a.sh, b.sh);
  EXPECT_EQ(a.irradiance_atlas, b.irradiance_atlas);
  ASSERT_EQ(a.stats.size(), 768u);
  for (size_t first : {size_t(0), size_t(512)}) {
    const size_t last = std::min(a.stats.size(), first + 512);
    uint64_t spent = 0, unbudgeted = 0;
    for (size_t p = first; p < last; ++p) spent += a.stats[p].rays, unbudgeted += unbounded.stats[p].rays;
    EXPECT_LE(spent, uint64_t(s.ray_budget) * (last - first)) << "block at " << first;
    EXPECT_GT(unbudgeted, uint64_t(s.ray_budget) * (last - first)) << "block at " << first << ": must bind";
  }
}

// Same bytes for any thread count, and --target-error spends rays where the noise is.
TEST(PathGather, DeterministicAndAdaptive) {
  DdgiSettings s;
  const Scene scene = lamp_room(s);
  DdgiResult a;
  DdgiReport ra;
  bake_on_one_and_two_threads(scene, s, a, ra);
  if (HasFatalFailure()) return;
  uint32_t min_rays = UINT32_MAX, max_rays = 0;
  for (const DdgiProbeStats& st : a.stats) {
    min_rays = std::min(min_rays, st.rays);
    max_rays = std::max(max_rays, st.rays);
    EXPECT_TRUE(st.relative_error < s.target_error || st.rays >= s.max_rays) << st.rays << " " << st.relative_error;
  }
  EXPECT_GT(max_rays, 64u);  // some probe needed more than one batch
  EXPECT_GT(ra.bounce_rays, 0u);
}

// --ray-budget: the mean rays per probe stays within the budget, the same for any thread count,
// and the batches it allows go only to probes the unbudgeted bake also found too noisy.
TEST(PathGather, RayBudgetBoundsTheMeanRaysAndGoesToNoisyProbes) {
  DdgiSettings s;
  const Scene scene = lamp_room(s);
  DdgiResult free_run, a, b;
  DdgiReport rf, ra, rb;
  ASSERT_TRUE(bake(scene, s, free_run, rf, 2));
  uint64_t free_total = 0;
  for (const DdgiProbeStats& st : free_run.stats) free_total += st.rays;
  s.ray_budget = 160;  // mean rays per probe: room for a few extra batches, not for all
  ASSERT_GT(free_total, uint64_t(s.ray_budget) * free_run.stats.size()) << "the budget must bind in this scene";
  ASSERT_TRUE(bake(scene, s, a, ra, 1));
  ASSERT_TRUE(bake(scene, s, b, rb, 2));
  EXPECT_EQ(a.sh, b.sh);
  EXPECT_EQ(a.irradiance_atlas, b.irradiance_atlas);
  uint64_t total = 0;
  size_t more = 0;
  for (size_t p = 0; p < a.stats.size(); ++p) {
    total += a.stats[p].rays;
    if (a.stats[p].rays > 64) {
      ++more;
      EXPECT_GT(free_run.stats[p].rays, 64u) << "probe " << p << " got a batch the unbudgeted bake did not need";
    }
  }
  EXPECT_LE(total, uint64_t(s.ray_budget) * a.stats.size());
  EXPECT_GT(more, 0u);
}

// A probe inside a single-sided solid sees back faces on every ray: after its first batch it is
// inside beyond doubt (ProbeBatches::inside), takes no more batches, and the block's budget is
// shared by the others alone: a binding budget of 160 rays a probe gives the 17 others 17 x 160
// between them, not the 18 x 160 minus the inside probe's batch that they would share if it still
// counted. Same bytes for any thread count.
TEST(PathGather, ProbeInsideGeometryStopsAfterItsFirstBatchAndLeavesTheBudget) {
  DdgiSettings s;
  Scene scene = lamp_room(s);
  test::add_box(scene, {0.3f, 0.3f, 0.3f}, {0.7f, 0.7f, 0.7f}, /*inward=*/false, test::add_material(scene, 0.6f));
  s.ray_budget = 160;
  DdgiResult a;
  DdgiReport ra;
  bake_on_one_and_two_threads(scene, s, a, ra);
  if (HasFatalFailure()) return;
  ASSERT_EQ(a.stats.size(), 18u);
  EXPECT_EQ(a.states[0], ProbeState::Inactive);  // the probe at (0.5, 0.5, 0.5), inside the solid
  EXPECT_EQ(a.stats[0].backface_fraction, 1.f);
  EXPECT_EQ(a.stats[0].rays, s.rays) << "one batch, then no more";
  uint64_t others = 0;
  for (size_t p = 1; p < a.stats.size(); ++p) {
    EXPECT_NE(a.states[p], ProbeState::Inactive) << "probe " << p;
    others += a.stats[p].rays;
  }
  const uint64_t share = uint64_t(s.ray_budget) * 17;
  EXPECT_LE(others, share);
  EXPECT_GT(others, share - s.rays) << "the budget must bind: the others spend it to within one batch";
}

namespace {

// Irradiance at a point under a rectangle of radiance L parallel to its surface, the rectangle
// spanning [0, a] x [0, b] at height h with one corner straight above the point: pi L times the
// differential form factor (Howell's catalogue, C-11).
double corner_irradiance(double L, double a, double b, double h) {
  const double x = a / h, y = b / h, sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  return L * 0.5 * (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy));
}

}  // namespace

// A small lamp (0.2 m square, L = 1000 cd/m^2) 1 m above a black floor: the irradiance at the
// point below it is 4 corner rectangles of the closed form. The reference's paths with their paired
// emitter samples (trace_surface_radiance, as the reconstruction check and the surface fit trace
// them) must find it within 1% from 256 pairs (0.5% over 64 such), and with far less noise than the same 256
// cosine-weighted paths alone, which meet a lamp of 0.04 sr only by chance: the spread of 64
// independent estimates at least 4x smaller.
TEST(PathGather, SurfaceEmitterSamplesFindASmallLampAndCutItsNoise) {
  Scene scene;
  test::add_quad(scene, {-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}, {0, 1, 0}, test::add_material(scene, 0.f));
  constexpr float kLe = 1000.f, kHalf = 0.1f, kHeight = 1.f;
  test::add_quad(scene, {-kHalf, kHeight, -kHalf}, {kHalf, kHeight, -kHalf}, {kHalf, kHeight, kHalf},
                 {-kHalf, kHeight, kHalf}, {0, -1, 0}, test::add_material(scene, 0.f, kLe));
  constexpr float kAbove = 1e-3f;  // the point's height over the floor
  const double expected = 4.0 * corner_irradiance(kLe, kHalf, kHalf, kHeight - kAbove);
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
  const EmitterTable emitters(scene);
  ASSERT_FALSE(emitters.empty());
  const Sky sky;
  const std::vector<kernels::ShadeLight> lights;
  const PathSetup path = make_path_setup(*prepared, lights, sky, emitters, 7, kReferenceBounces);
  const float3 n{0, 1, 0}, origin{0, kAbove, 0};
  constexpr uint32_t kPairs = 256, kEstimates = 64;
  const auto spread = [](const std::vector<double>& v, double& mean) {
    mean = 0.0;
    for (double x : v) mean += x;
    mean /= double(v.size());
    double var = 0.0;
    for (double x : v) var += (x - mean) * (x - mean);
    return std::sqrt(var / double(v.size() - 1));
  };
  std::vector<double> paired, alone;
  TraceCounters tc;
  for (uint32_t e = 0; e < kEstimates; ++e) {
    const uint64_t shift = kernels::rng_hash(e, kernels::kProbeLightShiftRay, 0, 1);
    double with = 0.0, without = 0.0;
    for (uint32_t r = 0; r < kPairs; ++r) {
      const uint64_t key = kernels::rng_hash(e, r, 0, 1);
      const float3 dir =
          kernels::sample_cosine_hemisphere(n, kernels::rng_uniform(key, 0), kernels::rng_uniform(key, 1));
      float u[3];
      kernels::probe_light_uniforms(shift, r, kPairs, u);
      with += trace_surface_radiance(path, origin, n, n, dir, true, u, key, tc).x;
      without += trace_radiance(path, origin, dir, key, tc).x;
    }
    paired.push_back(M_PI * with / kPairs);
    alone.push_back(M_PI * without / kPairs);
  }
  double mean_paired = 0.0, mean_alone = 0.0;
  const double sd_paired = spread(paired, mean_paired), sd_alone = spread(alone, mean_alone);
  std::printf("lamp irradiance %.4f: paired %.4f (sd %.4f), paths alone %.4f (sd %.4f)\n", expected, mean_paired,
              sd_paired, mean_alone, sd_alone);
  EXPECT_NEAR(paired.front(), expected, 0.01 * expected);  // one estimate of 256 pairs
  EXPECT_NEAR(mean_paired, expected, 0.005 * expected);
  EXPECT_LT(sd_paired * 4.0, sd_alone);
  // Below the geometric surface a path brings its emitter sample alone.
  float u[3] = {0.5f, 0.5f, 0.5f};
  const float3 below = trace_surface_radiance(path, origin, n, n, float3{0, -1, 0}, false, u, 1, tc);
  EXPECT_GT(below.x, 0.f);
}

namespace {

// A probe field answering one irradiance everywhere.
struct ConstantField : ProbeField {
  explicit ConstantField(float e) : e(e) {}
  float3 irradiance(const float3&, const float3&) const override { return float3{e, e, e}; }
  float e;
};

// Irradiance at a surface point from `pairs` cosine-weighted paths (each with its emitter sample),
// as the surface fit gathers it: pi / N times the sum (estimate `e` of several, keyed apart).
double surface_irradiance(const PathSetup& path, const float3& origin, const float3& n, uint32_t pairs, uint32_t e) {
  TraceCounters tc;
  const uint64_t shift = kernels::rng_hash(e, kernels::kProbeLightShiftRay, 0, 2);
  double sum = 0.0;
  for (uint32_t r = 0; r < pairs; ++r) {
    const uint64_t key = kernels::rng_hash(e, r, 0, 2);
    const float3 dir = kernels::sample_cosine_hemisphere(n, kernels::rng_uniform(key, 0), kernels::rng_uniform(key, 1));
    float u[3];
    kernels::probe_light_uniforms(shift, r, pairs, u);
    sum += trace_surface_radiance(path, origin, n, n, dir, true, u, key, tc).x;
  }
  return M_PI * sum / pairs;
}

}  // namespace

// A path lit by a probe field ends at its first hit: that hit's emission, the punctual lights
// there and albedo / pi times the field's irradiance; a first hit on an emitter goes on as a full
// path. Three answers known in closed form:
// * a dark box of albedo 0.5 whose field says E0 everywhere: every path reads 0.5 E0 exactly;
// * a furnace (albedo 0.8, walls emitting Le): every first hit is an emitter, where probes are not
//   read (those beside it see it at close range), so a field that is wildly wrong changes nothing:
//   the same estimate to the bit as full paths, near pi Le / (1 - rho);
// * a point facing down over a wide floor (albedo 0.4) under a vertical 1,000 lux sun, the field
//   dark: every path's first hit is sunlit floor, so the point reads 0.4 x 1,000 lux (the sun
//   reaches the first hit although no probe holds it).
TEST(PathGather, ProbeFieldEndsEachPathAtItsFirstHit) {
  const Sky sky;
  const std::vector<kernels::ShadeLight> none;
  const float3 inside{0.1f, -0.3f, 0.2f}, up{0, 1, 0};
  {
    Scene scene;
    test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, 0.5f));
    std::unique_ptr<PreparedScene> prepared;
    ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
    const EmitterTable emitters(scene);
    const ConstantField field(3.f);
    PathSetup path = make_path_setup(*prepared, none, sky, emitters, 7, kReferenceBounces);
    path.probe_field = &field;
    EXPECT_NEAR(surface_irradiance(path, inside, up, 256, 0), 1.5, 1e-4);
  }
  {
    Scene scene;
    constexpr float kRho = 0.8f, kLe = 2.f;
    test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, kRho, kLe));
    std::unique_ptr<PreparedScene> prepared;
    ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
    const EmitterTable emitters(scene);
    const double limit = M_PI * kLe / (1.0 - kRho);
    const ConstantField wrong{1e6f};
    const PathSetup full = make_path_setup(*prepared, none, sky, emitters, 7, kReferenceBounces);
    PathSetup one = full;
    one.probe_field = &wrong;
    const double a = surface_irradiance(one, inside, up, 4096, 0), b = surface_irradiance(full, inside, up, 4096, 0);
    std::printf("furnace limit %.4f: with a probe field %.4f, full paths %.4f\n", limit, a, b);
    EXPECT_EQ(a, b);
    EXPECT_NEAR(a, limit, 0.03 * limit);
  }
  {
    Scene scene;
    test::add_quad(scene, {-1000, 0, -1000}, {1000, 0, -1000}, {1000, 0, 1000}, {-1000, 0, 1000}, {0, 1, 0},
                   test::add_material(scene, 0.4f));
    std::unique_ptr<PreparedScene> prepared;
    ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
    const EmitterTable emitters(scene);
    SunLight sun;
    sun.lux = 1000.f;
    const ConstantField dark(0.f);
    const std::vector<kernels::ShadeLight> lights = shade_lights(scene, {sun});  // the setup points at them
    PathSetup path = make_path_setup(*prepared, lights, sky, emitters, 7, kReferenceBounces);
    path.probe_field = &dark;
    EXPECT_NEAR(surface_irradiance(path, float3{0, 1, 0}, float3{0, -1, 0}, 256, 0), 400.0, 0.4);
  }
}

// Both estimates from one path (the fit's both gather) are each the estimate traced alone, to the
// bit: the path traced whole is the path without a field, and what it records at its first hit
// is the path the field ends there. In a box of albedo 0.5 lit by a small lamp under its ceiling,
// so that paths meet the lamp (MIS with its samples), end on walls and go on past them.
TEST(PathGather, OnePathGivesBothEstimatesAsEachAlone) {
  Scene scene;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, 0.5f));
  test::add_quad(scene, {-0.2f, 0.95f, -0.2f}, {0.2f, 0.95f, -0.2f}, {0.2f, 0.95f, 0.2f}, {-0.2f, 0.95f, 0.2f},
                 {0, -1, 0}, test::add_material(scene, 0.f, 50.f));
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
  const EmitterTable emitters(scene);
  const Sky sky;
  const std::vector<kernels::ShadeLight> none;
  const ConstantField field(3.f);
  const PathSetup whole = make_path_setup(*prepared, none, sky, emitters, 7, kReferenceBounces);
  PathSetup lit = whole;
  lit.probe_field = &field;
  const float3 origin{0.1f, -0.9f, 0.2f}, n{0, 1, 0};
  const uint64_t shift = kernels::rng_hash(3, kernels::kProbeLightShiftRay, 0, 2);
  int differ = 0, lamp_paths = 0;
  for (uint32_t r = 0; r < 512; ++r) {
    const uint64_t key = kernels::rng_hash(3, r, 0, 2);
    const float3 dir = kernels::sample_cosine_hemisphere(n, kernels::rng_uniform(key, 0), kernels::rng_uniform(key, 1));
    float u[3];
    kernels::probe_light_uniforms(shift, r, 512, u);
    TraceCounters tc;
    float3 ended{-1.f, -1.f, -1.f};
    const float3 both = trace_surface_radiance(lit, origin, n, n, dir, true, u, key, tc, &ended);
    const float3 alone = trace_surface_radiance(whole, origin, n, n, dir, true, u, key, tc);
    const float3 ended_alone = trace_surface_radiance(lit, origin, n, n, dir, true, u, key, tc);
    EndedLight deferred;
    const float3 traced = trace_surface_radiance_ended(lit, origin, n, n, dir, true, u, key, tc, deferred);
    EXPECT_EQ(both.x, alone.x) << r;
    EXPECT_EQ(ended.x, ended_alone.x) << r;
    EXPECT_EQ(traced.x, both.x) << r;  // the field read later (EndedLight) gives the same bytes
    EXPECT_EQ(deferred.resolve(&field).x, ended.x) << r;
    differ += both.x != ended.x;
    lamp_paths += both.x == ended.x;  // the lamp's own surface: the path goes on alike
  }
  // The two estimates are not one: most paths go on past a wall, a few meet the lamp first.
  EXPECT_GT(differ, 400);
  EXPECT_GT(lamp_paths, 0);
}

// A path casts its vertex's shadow rays before it reads the albedo (PendingSurface, PunctualRays);
// a black surface ends the path there as before: nothing reflected, its rays neither counted nor
// followed. A grey floor under a 1000-lux sun at the zenith, seen straight down, reflects
// 0.4 x 1000 / pi cd/m^2 (the sky is black, so its bounce ray adds nothing) with one shadow ray
// and one bounce ray.
TEST(PathGather, ABlackSurfaceCastsNoCountedShadowRay) {
  for (const float albedo : {0.f, 0.4f}) {
    Scene scene;
    test::add_quad(scene, {-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}, {0, 1, 0},
                   test::add_material(scene, albedo));
    std::unique_ptr<PreparedScene> prepared;
    ASSERT_TRUE(PreparedScene::create(scene, Context{}, prepared));
    const EmitterTable emitters(scene);
    const Sky sky;
    SunLight sun;
    sun.direction = {0.f, -1.f, 0.f};
    sun.lux = 1000.f;
    const std::vector<kernels::ShadeLight> lights = shade_lights(scene, {sun});
    const PathSetup path = make_path_setup(*prepared, lights, sky, emitters, 7, kReferenceBounces);
    TraceCounters tc;
    const float3 l = trace_radiance(path, float3{0.f, 1.f, 0.f}, float3{0.f, -1.f, 0.f}, 1, tc);
    EXPECT_NEAR(l.x, albedo * 1000.0 / M_PI, 1e-3) << albedo;
    EXPECT_EQ(tc.shadow_rays, albedo > 0.f ? 1u : 0u) << albedo;
    EXPECT_EQ(tc.bounce_rays, albedo > 0.f ? 1u : 0u) << albedo;
  }
}
