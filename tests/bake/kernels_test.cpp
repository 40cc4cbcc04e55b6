// CPU kernels: SH basis, octahedral mapping and borders, ray generation, light falloff.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "kernels/integrate.h"
#include "kernels/octahedral.h"
#include "kernels/ray_gen.h"
#include "kernels/sh.h"
#include "kernels/shade.h"

using namespace gibake::kernels;

TEST(Sh, BasisIsOrthonormal) {
  const uint32_t n = 200000;
  double gram[9][9] = {};
  for (uint32_t i = 0; i < n; ++i) {
    float y[9];
    sh_basis(spherical_fibonacci(i, n), 2, y);
    for (int a = 0; a < 9; ++a)
      for (int b = 0; b < 9; ++b) gram[a][b] += double(y[a]) * y[b];
  }
  for (int a = 0; a < 9; ++a)
    for (int b = 0; b < 9; ++b) EXPECT_NEAR(gram[a][b] * 4.0 * M_PI / n, a == b ? 1.0 : 0.0, 2e-4) << a << "," << b;
}

TEST(Sh, UniformRadianceGivesPiL) {
  float sh[27] = {};
  sh[0] = sh[1] = sh[2] = 2.f * std::sqrt(float(M_PI));  // L = 1: coefficient sqrt(4pi)
  const float3 e = sh_irradiance(sh, 2, normalize(float3{0.3f, -0.5f, 0.8f}));
  EXPECT_NEAR(e.x, M_PI, 1e-4);
}

TEST(Sh, CapProjectionMatchesQuadrature) {
  const float3 axis = normalize(float3{0.2f, -0.7f, 0.4f});
  const float cos_half = 0.8f;
  float exact[9];
  sh_project_uniform_cap(axis, cos_half, 2, exact);
  const uint32_t n = 400000;
  double sum[9] = {};
  for (uint32_t i = 0; i < n; ++i) {
    const float3 d = spherical_fibonacci(i, n);
    if (dot(d, axis) < cos_half) continue;
    float y[9];
    sh_basis(d, 2, y);
    for (int c = 0; c < 9; ++c) sum[c] += y[c];
  }
  for (int c = 0; c < 9; ++c) EXPECT_NEAR(sum[c] * 4.0 * M_PI / n, exact[c], 2e-3) << c;
}

TEST(Octahedral, RoundTrip) {
  for (uint32_t i = 0; i < 1000; ++i) {
    const float3 d = spherical_fibonacci(i, 1000);
    float u, v;
    encode_oct(d, u, v);
    const float3 r = decode_oct(u, v);
    EXPECT_NEAR(dot(d, r), 1.f, 1e-5f);
  }
}

// A smooth function of direction sampled bilinearly through the borders stays continuous
// across the octahedron's folded edges.
TEST(Octahedral, BorderMakesBilinearSeamless) {
  const int res = 8, tile = res + 2;
  AtlasLayout layout;
  layout.counts[0] = 2;
  layout.res = res;
  std::vector<float> atlas(size_t(layout.width()) * layout.height(), 0.f);
  auto f = [](const float3& d) { return 1.f + 0.5f * d.x + 0.3f * d.y - 0.4f * d.z; };
  int ox, oy;
  layout.tile_origin(1, ox, oy);
  EXPECT_EQ(ox, tile);
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) atlas[size_t(oy + 1 + y) * layout.width() + ox + 1 + x] = f(oct_texel_direction(x, y, res));
  oct_fill_border(atlas.data(), layout.width(), 1, ox, oy, res);
  float worst = 0.f;
  for (uint32_t i = 0; i < 4000; ++i) {
    const float3 d = spherical_fibonacci(i, 4000);
    float s;
    oct_sample_bilinear(atlas.data(), layout.width(), 1, ox, oy, res, d, &s);
    worst = std::max(worst, std::fabs(s - f(d)));
  }
  // Linear in d, so only the octahedral distortion inside a texel remains (no seams: < 0.1).
  EXPECT_LT(worst, 0.1f);
}

TEST(RayGen, DeterministicAndUnit) {
  std::vector<float> a(64 * 3), b(64 * 3), c(64 * 3);
  generate_probe_rays(42, 7, 3, 64, a.data());
  generate_probe_rays(42, 7, 3, 64, b.data());
  generate_probe_rays(42, 7, 4, 64, c.data());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  for (int i = 0; i < 64; ++i) EXPECT_NEAR(length(load3(&a[i * 3])), 1.f, 1e-5f);
}

TEST(RayGen, PrecomputedFibonacciSetGivesTheSameBits) {
  for (uint32_t n : {1u, 7u, 64u, 256u, 1000u}) {
    std::vector<float> fib(n * 3), a(n * 3), b(n * 3);
    spherical_fibonacci_set(n, fib.data());
    for (uint32_t probe : {0u, 5u, 123456u}) {
      generate_probe_rays(9, probe, 2, n, a.data());
      generate_probe_rays_from_set(fib.data(), 9, probe, 2, n, b.data());
      EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float))) << n << " " << probe;
    }
  }
}

// The bucketed, branch-free depth filter equals the direct definition: every texel's moments are
// the pow(dot, 64)-weighted means over the rays within the cut-off cone, summed in ray order.
TEST(Integrate, DepthMomentsMatchBruteForce) {
  const DepthConeTable t = build_depth_cone_table(16);
  const int n = 256;
  std::vector<RaySample> rays(n);
  std::vector<float> dirs(n * 3);
  generate_probe_rays(3, 1, 0, n, dirs.data());
  for (int r = 0; r < n; ++r) {
    for (int a = 0; a < 3; ++a) rays[r].dir_depth[a] = dirs[r * 3 + a];
    rays[r].dir_depth[3] = 1.f + 0.01f * float((r * 37) % 101);
  }
  std::vector<float> out(16 * 16 * 2);
  integrate_depth(t, rays.data(), n, out.data());
  for (int tx = 0; tx < 256; ++tx) {
    const float3 td = load3(&t.directions[tx * 3]);
    float s0 = 0.f, s1 = 0.f, s2 = 0.f;
    for (int r = 0; r < n; ++r) {
      const float c = dot(td, load3(rays[r].dir_depth));
      if (c < t.cos_cutoff) continue;
      float w = c * c; w *= w; w *= w; w *= w; w *= w; w *= w;
      s0 += w * rays[r].dir_depth[3];
      s1 += w * rays[r].dir_depth[3] * rays[r].dir_depth[3];
      s2 += w;
    }
    if (s2 <= 0.f) continue;  // fallback path (nearest ray), not compared here
    EXPECT_EQ(out[tx * 2], s0 / s2) << tx;
    EXPECT_EQ(out[tx * 2 + 1], s1 / s2) << tx;
  }
}

TEST(Shade, PointAndSpotFalloffFollowGltf) {
  const float white[3] = {1, 1, 1};
  ShadeLight point = make_shade_light(kLightPoint, white, 100.f, float3{0, 2, 0}, float3{0, -1, 0}, 4.f, 0, 0.5f);
  LightSample s;
  ASSERT_TRUE(sample_light(point, float3{0, 0, 0}, s));
  const float window = 1.f - std::pow(2.f / 4.f, 4.f);
  EXPECT_NEAR(s.illuminance.x, 100.f / 4.f * window, 1e-4);
  EXPECT_FALSE(sample_light(point, float3{0, 7, 0}, s));  // beyond range
  ShadeLight spot = make_shade_light(kLightSpot, white, 100.f, float3{0, 2, 0}, float3{0, -1, 0}, 0.f, 0.2f, 0.4f);
  ASSERT_TRUE(sample_light(spot, float3{0, 0, 0}, s));  // on the axis: full
  EXPECT_NEAR(s.illuminance.x, 25.f, 1e-3);
  EXPECT_FALSE(sample_light(spot, float3{2, 0, 0}, s));  // 45 degrees: outside the cone
}

TEST(Integrate, DepthConeReachesEveryTexel) {
  const DepthConeTable t = build_depth_cone_table(16);
  std::vector<RaySample> rays(256);
  for (uint32_t i = 0; i < 256; ++i) {
    store3(rays[i].dir_depth, spherical_fibonacci(i, 256));
    rays[i].dir_depth[3] = 2.f;
  }
  std::vector<float> out(16 * 16 * 2);
  integrate_depth(t, rays.data(), 256, out.data());
  for (int i = 0; i < 256; ++i) {
    EXPECT_NEAR(out[i * 2], 2.f, 1e-5f);
    EXPECT_NEAR(out[i * 2 + 1], 4.f, 1e-4f);
  }
}

// Every texel a ray should touch (pow(dot,64) above the cutoff) is among its bucket's candidates.
TEST(Integrate, DepthConeCandidatesAreComplete) {
  const DepthConeTable t = build_depth_cone_table(16);
  size_t visited = 0;
  for (uint32_t i = 0; i < 20000; ++i) {
    const float3 d = spherical_fibonacci(i, 20000);
    int bx, by;
    oct_texel_of(d, t.bucket_res, bx, by);
    const int b = by * t.bucket_res + bx;
    visited += t.offsets[b + 1] - t.offsets[b];
    for (int j = 0; j < 256; ++j) {
      if (dot(load3(&t.directions[j * 3]), d) < t.cos_cutoff) continue;
      bool found = false;
      for (uint32_t k = t.offsets[b]; k < t.offsets[b + 1]; ++k) found = found || t.candidates[k] == j;
      ASSERT_TRUE(found) << "ray " << i << " texel " << j;
    }
  }
  EXPECT_LT(visited / 20000.0, 16.0);  // the point of the table: far fewer than 256 per ray
}
