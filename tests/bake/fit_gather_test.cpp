// The fit's truth from its two gathers (bake/ddgi/fit_gather.h), on light made up here with known
// answers: the rule must take the probe-lit light scaled to the whole paths' level where the
// probes are wrong by one factor over a region (far less noise than the whole paths), the whole
// paths where the probes' error varies from point to point, and the whole paths alone without a
// both gather.
#include "bake/ddgi/fit_gather.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "kernels/ray_gen.h"

namespace gibake {
namespace {

constexpr uint32_t kProbes = 64, kPointsAProbe = 4;

// A made-up point: its true light, its whole paths' halves (noise of relative size `f_noise`) and
// its ended paths' halves (`g_factor` times the truth, noise `g_noise`), all in one region.
FitPointLight point(double truth, double f_noise, double g_factor, double g_noise, uint32_t probe, uint64_t key) {
  auto draw = [&](uint32_t stream) { return 2.0 * kernels::rng_uniform(key, stream) - 1.0; };  // uniform -1..1
  FitPointLight p;
  p.probe = probe;
  p.region = {0, 0, 0, 0};
  for (int h = 0; h < 2; ++h) {
    p.f_half[h] = truth * (1.0 + f_noise * draw(uint32_t(h)));
    p.g_half[h] = g_factor * truth * (1.0 + g_noise * draw(uint32_t(2 + h)));
  }
  p.f = 0.5 * (p.f_half[0] + p.f_half[1]);
  p.g = 0.5 * (p.g_half[0] + p.g_half[1]);
  return p;
}

double truth_of(uint32_t i) { return 100.0 + 50.0 * std::sin(0.37 * double(i)); }

// Mean relative error against the made-up truth.
double mean_error(const std::vector<double>& values) {
  double e = 0.0;
  for (uint32_t i = 0; i < values.size(); ++i) e += std::fabs(values[i] / truth_of(i) - 1.0);
  return e / double(values.size());
}

std::vector<FitPointLight> points(double f_noise, double g_factor_even, double g_factor_odd, double g_noise) {
  std::vector<FitPointLight> out;
  for (uint32_t i = 0; i < kProbes * kPointsAProbe; ++i)
    out.push_back(point(truth_of(i), f_noise, i % 2 ? g_factor_odd : g_factor_even, g_noise, i / kPointsAProbe,
                        kernels::rng_hash(11, i, 0, 0)));
  return out;
}

std::vector<double> truths(const std::vector<FitTruth>& t) {
  std::vector<double> out;
  for (const FitTruth& x : t) out.push_back(x.truth);
  return out;
}

std::vector<double> whole(const std::vector<FitPointLight>& p) {
  std::vector<double> out;
  for (const FitPointLight& x : p) out.push_back(x.f);
  return out;
}

// Probes half as bright as the truth everywhere, their ended paths 2% noisy, the whole paths 40%:
// the rule scales the ended light back (R near 2, pooled over 256 points) and trusts it.
TEST(FitGather, ProbesWrongByOneFactorAreScaledToTheWholePaths) {
  const std::vector<FitPointLight> p = points(0.4, 0.5, 0.5, 0.02);
  const std::vector<FitTruth> t = fit_truths(p, true);
  const double ours = mean_error(truths(t)), paths = mean_error(whole(p));
  std::printf("probes at half the light: mean error %.3f blended, %.3f whole paths\n", ours, paths);
  EXPECT_GT(paths, 0.1);
  EXPECT_LT(ours, 0.04);
  EXPECT_LT(t[0].noise, 0.01);  // its expected relative variance is the ended light's and R's
}

// Probes wrong by a factor that differs from point to point (0.5 and 1.5 alternately), whole
// paths 3% noisy: R g misses every point by about half, so the rule keeps the whole paths.
TEST(FitGather, ProbesWrongFromPointToPointLeaveTheWholePaths) {
  const std::vector<FitPointLight> p = points(0.03, 0.5, 1.5, 0.02);
  const std::vector<FitTruth> t = fit_truths(p, true);
  const double ours = mean_error(truths(t)), paths = mean_error(whole(p));
  std::printf("probes wrong point by point: mean error %.3f blended, %.3f whole paths\n", ours, paths);
  EXPECT_LT(ours, paths + 0.01);
  EXPECT_LT(ours, 0.03);
}

// Without a both gather, and in a region whose ended light is black, each point's truth is its
// whole paths' light, with the noise of its probe's points pooled.
TEST(FitGather, WholePathsAloneWithoutBothOrEndedLight) {
  const std::vector<FitPointLight> p = points(0.2, 0.5, 0.5, 0.02);
  const std::vector<FitTruth> paths = fit_truths(p, false);
  std::vector<FitPointLight> black = p;
  for (FitPointLight& x : black) x.g = x.g_half[0] = x.g_half[1] = 0.0;
  const std::vector<FitTruth> dark = fit_truths(black, true);
  double variance = 0.0, squares = 0.0;
  for (uint32_t i = 0; i < kPointsAProbe; ++i) {
    variance += 0.25 * (p[i].f_half[0] - p[i].f_half[1]) * (p[i].f_half[0] - p[i].f_half[1]);
    squares += p[i].f * p[i].f;
  }
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(paths[i].truth, p[i].f) << i;
    EXPECT_EQ(dark[i].truth, p[i].f) << i;
  }
  EXPECT_NEAR(paths[0].noise, variance / squares, 1e-12);
  EXPECT_GT(paths[0].noise, 0.0);
}

// A point whose light is not a number (a path gone wrong) has a truth that is not one either (the
// fit leaves such a point out) and changes no other point's: every other truth is the one it has
// without that point's light at all.
TEST(FitGather, APointThatIsNotANumberChangesNoOther) {
  const std::vector<FitPointLight> p = points(0.4, 0.5, 0.5, 0.02);
  std::vector<FitPointLight> bad = p, gone = p;
  bad[5].g = bad[5].g_half[1] = std::nan("");
  bad[9].f = bad[9].f_half[0] = std::numeric_limits<double>::infinity();
  for (size_t i : {size_t(5), size_t(9)})
    gone[i].f = gone[i].g = gone[i].f_half[0] = gone[i].f_half[1] = gone[i].g_half[0] = gone[i].g_half[1] =
        std::nan("");
  for (bool both : {false, true}) {
    const std::vector<FitTruth> a = fit_truths(bad, both), b = fit_truths(gone, both);
    EXPECT_FALSE(std::isfinite(a[9].truth)) << both;
    for (size_t i = 0; i < p.size(); ++i) {
      if (i == 9 || (both && i == 5)) continue;
      EXPECT_TRUE(std::isfinite(a[i].truth)) << i;
      if (i != 5) {
        EXPECT_EQ(a[i].truth, b[i].truth) << i << " " << both;
      }
    }
  }
}

// Regions are apart: a second region whose probes are right keeps its own ratio of 1.
TEST(FitGather, EachRegionHasItsOwnRatio) {
  std::vector<FitPointLight> p = points(0.01, 0.5, 0.5, 0.01);
  for (size_t i = p.size() / 2; i < p.size(); ++i) {
    p[i].region = {0, 1, 0, 0};
    for (int h = 0; h < 2; ++h) p[i].g_half[h] *= 2.0;
    p[i].g *= 2.0;
  }
  const std::vector<FitTruth> t = fit_truths(p, true);
  for (size_t i = 0; i < p.size(); ++i) EXPECT_NEAR(t[i].truth / truth_of(uint32_t(i)), 1.0, 0.03) << i;
  const float a[3] = {3.9f, 0.f, 0.f}, b[3] = {4.1f, 0.f, 0.f};
  EXPECT_NE(fit_region(0, a, 1.f), fit_region(0, b, 1.f));  // four spacings a cell
  EXPECT_EQ(fit_region(0, a, 1.f), fit_region(0, a, 1.f));
  EXPECT_NE(fit_region(0, a, 1.f), fit_region(1, a, 1.f));
}

}  // namespace
}  // namespace gibake
