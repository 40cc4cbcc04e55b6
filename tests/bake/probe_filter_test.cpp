// The probe filter (bake/ddgi/probe_filter.h) against answers known without it: a furnace grid
// (every probe's truth is pi Le / (1 - rho)) whose noise must drop while its mean stays put; a wall
// between two rooms of different light that probes must not blend across (visibility from the depth
// moments); true changes far above the noise (a steep ramp, a curved falloff) kept; thread-count
// determinism of a whole bake. Shards + merge against the one-go bake: tests/bake/shard_merge_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "kernels/octahedral.h"
#include "tests/bake/scene_builders.h"
#include "tests/bake/test_backend.h"
#include "tests/support/probe_grid.h"

using namespace gibake;

namespace {

Status bake(const Scene& scene, const DdgiSettings& s, DdgiResult& r, unsigned threads = 0) {
  Context ctx;
  ctx.threads = threads;
  DdgiReport rep;
  return bake_ddgi(scene, test::on_test_backend(s), ctx, r, rep);
}

// Mean irradiance over directions of probe p (lux), from L00 (grey scenes: the red channel).
double mean_irradiance(const DdgiResult& r, int32_t p) {
  return M_PI * r.sh[size_t(p) * size_t(r.desc.sh_coefficients()) * 3] / std::sqrt(4 * M_PI);
}

struct Spread {
  double mean = 0, rms = 0;  // mean and RMS relative deviation from `truth`
};
Spread spread(const DdgiResult& r, double truth) {
  Spread s;
  const int32_t n = r.desc.probe_count();
  for (int32_t p = 0; p < n; ++p) {
    const double e = mean_irradiance(r, p) / truth - 1.0;
    s.mean += e / n;
    s.rms += e * e / n;
  }
  s.rms = std::sqrt(s.rms);
  return s;
}

// RMS relative deviation of every interior irradiance texel from `truth` (red channel).
double atlas_rms(const DdgiResult& r, double truth) {
  kernels::AtlasLayout layout;
  for (int a = 0; a < 3; ++a) layout.counts[a] = r.desc.counts[a];
  layout.res = kIrradianceTexels;
  layout.planes_per_row = r.atlas_planes_per_row;
  double sum = 0;
  size_t count = 0;
  for (int32_t p = 0; p < r.desc.probe_count(); ++p) {
    int ox, oy;
    layout.tile_origin(p, ox, oy);
    for (int y = 1; y <= kIrradianceTexels; ++y)
      for (int x = 1; x <= kIrradianceTexels; ++x) {
        const double e = r.irradiance_atlas[(size_t(oy + y) * r.irradiance_width + size_t(ox + x)) * 4] / truth - 1;
        sum += e * e;
        ++count;
      }
  }
  return std::sqrt(sum / double(count));
}

// A closed furnace (albedo 0.8: long roulette paths, heavy-tailed noise) seen by 216 probes at 32
// rays each: over 10% noise per probe. The filter must cut the probes' RMS error to under 60% of
// it, and leave the grid's mean where it was: within 5% of the per-probe noise of the unfiltered
// mean (a weighted mean of the same probes moves it by a fraction of that), and within 4 standard
// errors of the mean (rms / sqrt(216)) of the truth. Weights that depend on the values (1/s^2 with
// s from each probe's own estimate) move it by over 10% of the noise, low, and fail.
TEST(ProbeFilter, FurnaceNoiseDropsAndTheMeanStays) {
  Scene scene;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, 0.8f, 2.f));
  const double truth = M_PI * 2.0 / (1.0 - 0.8);
  DdgiSettings s = test::probe_grid({-0.75f, -0.75f, -0.75f}, {0.75f, 0.75f, 0.75f}, {6, 6, 6}, 32);
  s.relocate = false;
  s.seed = 7;
  DdgiResult off, on;
  ASSERT_TRUE(bake(scene, s, off));
  s.filter.enabled = true;
  ASSERT_TRUE(bake(scene, s, on));
  const Spread a = spread(off, truth), b = spread(on, truth);
  std::printf("furnace grid: rms error %.4f -> %.4f, mean bias %+.4f -> %+.4f (truth %.4f lux)\n", a.rms, b.rms,
              a.mean, b.mean, truth);
  ASSERT_GT(a.rms, 0.03);  // noisy enough to mean something
  EXPECT_LT(b.rms, 0.6 * a.rms);
  EXPECT_LT(std::fabs(b.mean - a.mean), 0.05 * a.rms);
  EXPECT_LT(std::fabs(b.mean), 4 * a.rms / std::sqrt(216.0));
  // The irradiance atlas is filtered with the same weights: its noise drops too.
  EXPECT_LT(atlas_rms(on, truth), 0.6 * atlas_rms(off, truth));
}

// A synthetic result: n probes along x (1 x 1 x n grid, 0.5 m apart), one SH coefficient set per
// probe (grey, only L00 set to give mean irradiance `value[i]`), relative error `rel`, depth
// moments of a far miss everywhere unless a wall is put in.
DdgiResult line_of_probes(const std::vector<double>& value, float rel) {
  DdgiResult r;
  const int n = int(value.size());
  r.desc.counts = {n, 1, 1};
  r.desc.grid_min = {0, 0, 0};
  r.desc.grid_max = {0.5f * (n - 1), 0, 0};
  r.desc.spacing = {0.5f, 0, 0};
  r.desc.sh_order = 2;
  r.desc.max_distance = 100.f;
  const size_t coefs = 27;
  r.sh.assign(coefs * n, 0.f);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) r.sh[coefs * i + c] = float(value[i] * std::sqrt(4 * M_PI) / M_PI);
  r.offsets.assign(3 * n, 0.f);
  r.states.assign(n, ProbeState::Active);
  r.stats.assign(n, DdgiProbeStats{});
  for (auto& st : r.stats) st.relative_error = rel;
  r.depth_width = n * (kDepthTexels + 2);
  r.depth_height = kDepthTexels + 2;
  r.depth_atlas.assign(size_t(r.depth_width) * r.depth_height * 2, 0.f);
  for (size_t t = 0; t < r.depth_atlas.size(); t += 2) {
    r.depth_atlas[t] = 100.f;
    r.depth_atlas[t + 1] = 100.f * 100.f;
  }
  return r;
}

// A wall between probes i and i+1, 0.05 m from each: their depth moments towards it (the texels
// whose direction points at it) read 0.05 m.
void wall_between(DdgiResult& r, int i) {
  const int tile = kDepthTexels + 2;
  for (int p : {i, i + 1}) {
    const float side = p == i ? 1.f : -1.f;
    for (int y = 0; y < kDepthTexels; ++y)
      for (int x = 0; x < kDepthTexels; ++x) {
        if (side * kernels::oct_texel_direction(x, y, kDepthTexels).x < 0.2f) continue;
        float* m = &r.depth_atlas[(size_t(y + 1) * r.depth_width + size_t(p * tile + x + 1)) * 2];
        m[0] = 0.05f;
        m[1] = 0.05f * 0.05f;
      }
    kernels::oct_fill_border(r.depth_atlas.data(), r.depth_width, 2, p * tile, 0, kDepthTexels);
  }
}

// A wall between a bright room (probes 0..3) and a darker one (4..7) whose light differs by less
// than the probes' noise (20% against 30% each), so only visibility can keep them apart: with
// every neighbour of equal value on its own side, each probe must come out exactly as it went in.
TEST(ProbeFilter, NoBlendingThroughAWall) {
  std::vector<double> value = {1.2, 1.2, 1.2, 1.2, 1.0, 1.0, 1.0, 1.0};
  DdgiResult r = line_of_probes(value, 0.3f);
  wall_between(r, 3);
  ProbeFilterSettings fs;
  fs.enabled = true;
  ProbeFilterReport rep;
  filter_probes(r, fs, rep);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(mean_irradiance(r, i), value[i], 1e-5) << "probe " << i;
  // Without the wall the same values do blend (the test above is about visibility, not noise).
  DdgiResult open = line_of_probes(value, 0.3f);
  filter_probes(open, fs, rep);
  EXPECT_GT(std::fabs(mean_irradiance(open, 3) - 1.2), 0.02);
}

// True changes far above the noise (relative error 2%): a ramp rising 25% a probe (geometric) and a
// curved falloff 1/(1+x)^2. Each probe must keep its value within 0.5%, a quarter of its own noise.
TEST(ProbeFilter, StrongGradientsAreKept) {
  std::vector<double> ramp, falloff;
  for (int i = 0; i < 10; ++i) {
    ramp.push_back(std::pow(1.25, i));
    falloff.push_back(10.0 / ((1.0 + 0.5 * i) * (1.0 + 0.5 * i)));
  }
  for (const auto* values : {&ramp, &falloff}) {
    DdgiResult r = line_of_probes(*values, 0.02f);
    ProbeFilterSettings fs;
    fs.enabled = true;
    ProbeFilterReport rep;
    filter_probes(r, fs, rep);
    for (int i = 0; i < 10; ++i)
      EXPECT_NEAR(mean_irradiance(r, i) / (*values)[i], 1.0, 0.005) << "probe " << i;
  }
}

// The whole bake with the filter: the same bytes on 1 thread and on all of them.
TEST(ProbeFilter, SameResultForAnyThreadCount) {
  Scene scene;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, 0.6f, 1.f));
  test::add_box(scene, {-0.3f, -1.f, -0.3f}, {0.3f, 0.2f, 0.3f}, /*inward=*/false, test::add_material(scene, 0.5f));
  DdgiSettings s = test::probe_grid({-0.8f, -0.8f, -0.8f}, {0.8f, 0.8f, 0.8f}, {9, 9, 9}, 16);
  s.filter.enabled = true;
  DdgiResult one, all;
  ASSERT_TRUE(bake(scene, s, one, 1));
  ASSERT_TRUE(bake(scene, s, all, 0));
  EXPECT_TRUE(one.sh == all.sh);
  EXPECT_TRUE(one.irradiance_atlas == all.irradiance_atlas);
}

}  // namespace
