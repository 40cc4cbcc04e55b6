// Probe grids whose layers lie exactly on the planes of a closed room: no probe may end behind a
// plane, and the loader's sampler must give the furnace's irradiance everywhere on the walls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "tests/bake/scene_builders.h"
#include "tests/support/probe_grid.h"

using namespace gibake;

namespace {

constexpr float kHalf = 1.f;  // the room is [-1, 1]^3, planes facing in

// A grid of `n` probes per axis from -kHalf to kHalf: its outer layers lie on the room's planes.
DdgiSettings grid_on_planes(int n, uint32_t rays) {
  DdgiSettings s = test::probe_grid({-kHalf, -kHalf, -kHalf}, {kHalf, kHalf, kHalf}, {n, n, n}, rays);
  s.seed = 7;
  return s;
}

Status bake(const Scene& scene, const DdgiSettings& s, DdgiResult& r) {
  Context ctx;
  DdgiReport rep;
  return bake_ddgi(scene, s, ctx, r, rep);
}

// Final positions (rest + offset) of every probe.
std::vector<Vec3f> positions(const DdgiResult& r) {
  std::vector<Vec3f> out;
  const DdgiVolumeDesc& d = r.desc;
  for (int32_t z = 0; z < d.counts[2]; ++z)
    for (int32_t y = 0; y < d.counts[1]; ++y)
      for (int32_t x = 0; x < d.counts[0]; ++x) {
        const size_t p = size_t(x + d.counts[0] * (y + d.counts[1] * z));
        const int32_t c[3] = {x, y, z};
        Vec3f v{};
        for (int a = 0; a < 3; ++a) v[a] = d.grid_min[a] + d.spacing[a] * float(c[a]) + r.offsets[p * 3 + a];
        out.push_back(v);
      }
  return out;
}

// The furnace's answer on `samples` points per wall side, 1 mm in front of each wall, facing into
// the room: the smallest and largest irradiance (red) the loader's sampler gives.
std::pair<double, double> wall_irradiance_range(const DdgiResult& r, int samples) {
  std::vector<uint8_t> bytes;
  BakeOutputs out;
  out.ddgi = &r;
  BakeFileOptions options;
  options.atlas = FloatPrecision::Full;
  EXPECT_TRUE(build_bake_file(out, options, bytes));
  loader::BakeFile file;
  EXPECT_TRUE(file.open(std::move(bytes)).ok());
  const loader::DdgiVolume& v = file.ddgi_volumes().at(0);
  double lo = 1e30, hi = -1e30;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < samples; ++i)
        for (int j = 0; j < samples; ++j) {
          const float s = side ? 1.f : -1.f;
          loader::Vec3 p{}, n{0.f, 0.f, 0.f};
          p[axis] = s * (kHalf - 1e-3f);
          // Up to the room's edges (the first and last points 1 mm from them).
          p[(axis + 1) % 3] = -kHalf + 1e-3f + (2.f * kHalf - 2e-3f) * float(i) / float(samples - 1);
          p[(axis + 2) % 3] = -kHalf + 1e-3f + (2.f * kHalf - 2e-3f) * float(j) / float(samples - 1);
          n[axis] = -s;
          const double e = v.sample_irradiance(p, n)[0];
          lo = std::min(lo, e);
          hi = std::max(hi, e);
        }
  return {lo, hi};
}

}  // namespace

// Every probe of grids whose outer layers lie on the planes of a closed room ends strictly inside
// the room, in front of every plane -- single-sided planes and double-sided ones (whose back side
// the relocation rays see as front faces), at three spacings. Where a rest position lies exactly
// on a plane, rounding decides which side its rays leave from; a probe pushed to the back of a
// double-sided wall sees only the void and the walls' unlit outside.
TEST(DdgiRelocation, NoProbeEndsBehindAPlaneOfTheRoom) {
  for (bool double_sided : {false, true})
    for (int n : {5, 9, 17}) {
      Scene scene;
      test::add_box(scene, {-kHalf, -kHalf, -kHalf}, {kHalf, kHalf, kHalf}, /*inward=*/true,
                    test::add_material(scene, 0.5f, 1.f, double_sided));
      DdgiResult r;
      ASSERT_TRUE(bake(scene, grid_on_planes(n, 64), r));
      int behind = 0, inside = 0;
      for (const Vec3f& p : positions(r)) {
        bool in_front = true;
        for (int a = 0; a < 3; ++a) in_front = in_front && std::fabs(p[a]) < kHalf;
        (in_front ? inside : behind)++;
        if (!in_front && behind <= 3)
          ADD_FAILURE() << (double_sided ? "double" : "single") << "-sided, " << n << "^3: probe at " << p[0] << ","
                        << p[1] << "," << p[2] << " is behind a plane of the room";
      }
      EXPECT_EQ(behind, 0) << (double_sided ? "double" : "single") << "-sided planes, " << n << "^3 probes";
      EXPECT_EQ(inside, n * n * n);
    }
}

// A furnace: a closed room [-1, 1]^3 whose every plane emits Le and reflects albedo rho. Every
// point inside sees the same radiance in every direction, so every wall point has the same
// irradiance whatever the probes' positions: with the probe-feedback gather's N bounces,
// E = pi Le (1 + rho + ... + rho^N) = pi Le (1 - rho^(N+1)) / (1 - rho), which N = 16 puts within
// 2e-5 of the converged pi Le / (1 - rho); every ray sees Le and the probes' own uniform light, so
// the bake has no noise to hide a dark sample in. Baked with the probe grid's layers on the planes
// at three spacings, single- and double-sided walls (probes that go behind a double-sided wall
// see its outside: Le one way, the void the other), and sampled 1 mm in front of every wall as an
// engine's loader samples, 6 x 25 x 25 points: every sample within 1% of E.
TEST(DdgiRelocation, FurnaceWithProbeLayersOnTheWalls) {
  const float rho = 0.5f, le = 1.f;
  const int bounces = 16;
  const double expected = M_PI * le * (1.0 - std::pow(rho, bounces + 1)) / (1.0 - rho);
  for (bool double_sided : {true, false})
    for (int n : {5, 9, 17}) {
      Scene scene;
      test::add_box(scene, {-kHalf, -kHalf, -kHalf}, {kHalf, kHalf, kHalf}, /*inward=*/true,
                    test::add_material(scene, rho, le, double_sided));
      DdgiSettings s = grid_on_planes(n, 128);
      s.gather = Gather::Probes;
      s.bounces = bounces;
      DdgiResult r;
      ASSERT_TRUE(bake(scene, s, r));
      const auto [lo, hi] = wall_irradiance_range(r, 25);
      std::printf("furnace, %s-sided walls, %d^3 probes (%.3g m): wall irradiance %.4f..%.4f lux, exact %.4f\n",
                  double_sided ? "double" : "single", n, 2.0 * kHalf / (n - 1), lo, hi, expected);
      EXPECT_GT(lo, 0.99 * expected) << n << "^3, " << (double_sided ? "double" : "single") << "-sided";
      EXPECT_LT(hi, 1.01 * expected) << n << "^3, " << (double_sided ? "double" : "single") << "-sided";
    }
}
