// Coarse depth tiles (bake/ddgi/depth_tiles.h): the rule that defines a coarse texel, checked on
// every texel of a random atlas, the octahedral border the samplers rely on, and the layout the
// format's volume record promises (docs/FORMAT.md "Atlas layout"). What the rule does to the
// picture, against the path-traced truth: tests/preview/picture_cli_test.cpp (PictureDepthTiles).
#include "bake/ddgi/depth_tiles.h"

#include <gtest/gtest.h>

#include <random>

#include "kernels/octahedral.h"

namespace gibake {
namespace {

// A result of 3x5x2 probes with planes_per_row 2 (three bands), each interior texel random moments
// (mean in [0.1, 10) m, mean^2 >= mean^2), borders filled as the bake fills them.
DdgiResult random_result(uint32_t seed) {
  DdgiResult r;
  r.desc.counts = {3, 5, 2};
  r.atlas_planes_per_row = 2;
  kernels::AtlasLayout l;
  for (int a = 0; a < 3; ++a) l.counts[a] = r.desc.counts[a];
  l.res = kDepthTexels;
  l.planes_per_row = 2;
  r.depth_width = l.width();
  r.depth_height = l.height();
  r.depth_atlas.assign(size_t(l.width()) * size_t(l.height()) * 2, -1.f);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> mean(0.1f, 10.f), spread(0.f, 1.f);
  for (int p = 0; p < r.desc.probe_count(); ++p) {
    int ox, oy;
    l.tile_origin(p, ox, oy);
    for (int y = 1; y <= kDepthTexels; ++y)
      for (int x = 1; x <= kDepthTexels; ++x) {
        float* t = &r.depth_atlas[(size_t(oy + y) * size_t(l.width()) + size_t(ox + x)) * 2];
        t[0] = mean(rng);
        t[1] = t[0] * t[0] + spread(rng);
      }
    kernels::oct_fill_border(r.depth_atlas.data(), l.width(), 2, ox, oy, kDepthTexels);
  }
  return r;
}

const float* texel(const std::vector<float>& atlas, int width, int x, int y) {
  return &atlas[(size_t(y) * size_t(width) + size_t(x)) * 2];
}

TEST(DepthTiles, OnlyDivisorsOfTheBakedTileAreValid) {
  for (int t : {16, 8, 4}) EXPECT_TRUE(valid_depth_tile(t)) << t;
  for (int t : {0, 1, 2, 6, 12, 32}) EXPECT_FALSE(valid_depth_tile(t)) << t;
}

// Every coarse texel holds exactly the moments of one of the fine texels it covers, the one with the
// smallest mean: never farther than any of them (so no occluder is lost), never a mixture.
TEST(DepthTiles, ACoarseTexelIsTheNearestOfTheTexelsItCovers) {
  for (int interior : {8, 4}) {
    const DdgiResult fine = random_result(7);
    DdgiResult coarse = fine;
    coarsen_depth_atlas(coarse, interior);
    kernels::AtlasLayout from, to;
    for (int a = 0; a < 3; ++a) from.counts[a] = to.counts[a] = fine.desc.counts[a];
    from.planes_per_row = to.planes_per_row = 2;
    from.res = kDepthTexels;
    to.res = interior;
    ASSERT_EQ(coarse.depth_tile, interior);
    ASSERT_EQ(coarse.depth_width, to.width());
    ASSERT_EQ(coarse.depth_height, to.height());
    ASSERT_EQ(coarse.depth_atlas.size(), size_t(to.width()) * size_t(to.height()) * 2);
    const int factor = kDepthTexels / interior;
    for (int p = 0; p < fine.desc.probe_count(); ++p) {
      int fx, fy, cx, cy;
      from.tile_origin(p, fx, fy);
      to.tile_origin(p, cx, cy);
      for (int y = 0; y < interior; ++y)
        for (int x = 0; x < interior; ++x) {
          const float* c = texel(coarse.depth_atlas, to.width(), cx + 1 + x, cy + 1 + y);
          bool one_of_them = false;
          for (int j = 0; j < factor; ++j)
            for (int i = 0; i < factor; ++i) {
              const float* f = texel(fine.depth_atlas, from.width(), fx + 1 + x * factor + i, fy + 1 + y * factor + j);
              EXPECT_LE(c[0], f[0]) << "probe " << p << " texel " << x << "," << y;
              one_of_them = one_of_them || (c[0] == f[0] && c[1] == f[1]);
            }
          EXPECT_TRUE(one_of_them) << "probe " << p << " texel " << x << "," << y;
        }
    }
  }
}

// The border: RTXGI's rule (edges mirrored, corners from the opposite corner), checked against the
// interior texel each border texel must copy, so bilinear filtering across the fold is seamless.
TEST(DepthTiles, BordersMirrorTheCoarseInterior) {
  DdgiResult r = random_result(11);
  coarsen_depth_atlas(r, 8);
  kernels::AtlasLayout l;
  for (int a = 0; a < 3; ++a) l.counts[a] = r.desc.counts[a];
  l.res = 8;
  l.planes_per_row = 2;
  const int n = 8, w = l.width();
  auto same = [&](int ox, int oy, int bx, int by, int sx, int sy) {
    const float *b = texel(r.depth_atlas, w, ox + bx, oy + by), *s = texel(r.depth_atlas, w, ox + sx, oy + sy);
    return b[0] == s[0] && b[1] == s[1] && b[0] > 0.f;
  };
  for (int p = 0; p < r.desc.probe_count(); ++p) {
    int ox, oy;
    l.tile_origin(p, ox, oy);
    for (int i = 1; i <= n; ++i) {
      EXPECT_TRUE(same(ox, oy, i, 0, n + 1 - i, 1)) << p << " top " << i;
      EXPECT_TRUE(same(ox, oy, i, n + 1, n + 1 - i, n)) << p << " bottom " << i;
      EXPECT_TRUE(same(ox, oy, 0, i, 1, n + 1 - i)) << p << " left " << i;
      EXPECT_TRUE(same(ox, oy, n + 1, i, n, n + 1 - i)) << p << " right " << i;
    }
    EXPECT_TRUE(same(ox, oy, 0, 0, n, n));
    EXPECT_TRUE(same(ox, oy, n + 1, n + 1, 1, 1));
  }
}

TEST(DepthTiles, TheFullTileAndAnEmptyAtlasAreLeftAlone) {
  DdgiResult r = random_result(3);
  const std::vector<float> before = r.depth_atlas;
  coarsen_depth_atlas(r, kDepthTexels);
  EXPECT_EQ(r.depth_atlas, before);
  DdgiResult empty;
  coarsen_depth_atlas(empty, 8);
  EXPECT_TRUE(empty.depth_atlas.empty());
  EXPECT_EQ(empty.depth_tile, kDepthTexels);
}

}  // namespace
}  // namespace gibake
