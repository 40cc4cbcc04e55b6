// `preview --explain` against the white furnace (tests/support/white_furnace.h): every wall point
// and every probe position sees the same irradiance, pi Le sum_{k <= bounces + 1} rho^k, so each
// path-traced figure of the explanation has that answer, known without our code, and the baked
// one too (within the bake's noise). The probes it lists must be the sampler's: their shares sum to
// 1 over the two blended volumes, and their baked values weighed by the shares give the sampler's.
#include "bake/preview/explain.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "io/bakefile/bake_file.h"
#include "tests/loader/multi_volume.h"
#include "tests/support/white_furnace.h"

namespace gibake {
namespace {

struct Furnace : test::FurnaceBox {
  loader::BakeFile two;  // a coarse volume over the box and a finer one in a corner
};

void make_furnace(Furnace& f) {
  test::add_furnace_box(f);
  DdgiResult coarse, fine;
  DdgiReport report;
  ASSERT_TRUE(bake_ddgi(f.scene, test::furnace_probes({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f}, 3), Context{}, coarse,
                        report));
  ASSERT_TRUE(
      bake_ddgi(f.scene, test::furnace_probes({-0.9f, -0.9f, -0.9f}, {0.f, 0.f, 0.f}, 4), Context{}, fine, report));
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(test::multi_volume_bytes({&coarse, &fine}, BakeFileOptions{}, bytes,
                                       "{\"settings\":" + coarse.settings_json + "}"));
  ASSERT_FALSE(f.two.open(std::move(bytes)));
  test::prepare_furnace_box(f);
}

// A view from inside the box at the wall x = -1 near (-1, 0.2, -0.5), where the finer volume's fade
// band (0.15 to 0.3 beyond its probes along y) overlaps the coarse volume; paths that end where the
// bake's do, so the furnace's sum is the answer.
PreviewSettings corner_view() {
  PreviewSettings s;
  s.width = s.height = 32;
  s.camera_given = true;
  s.eye = {0.3f, 0.2f, -0.5f};
  s.target = {-1.f, 0.2f, -0.5f};
  s.fov_deg = 60.f;
  s.bounces = test::kFurnaceBounces;
  s.roulette_depth = 16;
  return s;
}

double furnace_irradiance() {
  double sum = 0.0, rho_k = 1.0;
  for (int k = 0; k <= test::kFurnaceBounces + 1; ++k, rho_k *= test::kFurnaceRho) sum += rho_k;
  return kernels::kPi * test::kFurnaceLe * sum;
}

void expect_truth(const TracedIrradiance& t, double expected, const char* what) {
  // Four standard errors of the estimate (at least 1%): roulette-free paths of a furnace vary little.
  EXPECT_NEAR(t.lux / expected, 1.0, std::max(4.0 * t.relative_error, 0.01)) << what;
  EXPECT_GT(t.relative_error, 0.0) << what;
}

TEST(Explain, FurnacePixelAndItsProbesReadTheFurnacesAnswer) {
  Furnace f;
  make_furnace(f);
  const double expected = furnace_irradiance();
  ExplainSettings es;
  es.x = 16;
  es.y = 16;
  es.paths = 2048;
  ExplainedPixel px;
  ASSERT_TRUE(explain_pixel(*f.prepared, f.two, corner_view(), es, Context{}, px));
  ASSERT_TRUE(px.hit);
  std::printf("%s", explain_text(px).c_str());
  expect_truth(px.here, expected, "here");
  ASSERT_EQ(px.along_normal.size(), 3u);
  for (const auto& [metres, traced] : px.along_normal) {
    EXPECT_GT(metres, 0.f);
    expect_truth(traced, expected, "along the normal");
  }
  // The bake's own answer: 256 rays a probe (the furnace tests' 2%).
  EXPECT_NEAR(px.baked_lux / expected, 1.0, 0.02);
  EXPECT_NEAR(px.exact_probes_lux / expected, 1.0, 0.02);
  // Both volumes weigh here, and the listed probes are exactly the sampler's.
  ASSERT_GE(px.probes.size(), 2u);
  bool volume[2] = {false, false};
  double shares = 0.0, blended = 0.0;
  for (const ExplainedProbe& p : px.probes) {
    ASSERT_LT(p.volume, 2u);
    volume[p.volume] = true;
    shares += p.share;
    blended += p.share * p.baked_lux;
    EXPECT_GT(p.weight.weight, 0.f);
    EXPECT_NEAR(
        p.weight.weight,
        std::max(p.weight.backface * p.weight.visibility, loader::SampleOptions{}.min_weight) * p.weight.trilinear,
        1e-6f);
    expect_truth(p.traced, expected, "at a probe");
  }
  EXPECT_TRUE(volume[0] && volume[1]);
  // Each listed volume's sight: the largest back-face x visibility weight of its probes listed.
  ASSERT_EQ(px.sights.size(), 2u);
  for (const auto& [v, sight] : px.sights) {
    float largest = 0.f;
    for (const ExplainedProbe& p : px.probes)
      if (p.volume == v) largest = std::max(largest, p.weight.backface * p.weight.visibility);
    EXPECT_FLOAT_EQ(sight, largest) << v;
    EXPECT_GE(sight, GIBAKE_DDGI_FULL_SIGHT) << v;  // the furnace's probes see the wall
  }
  EXPECT_NE(explain_text(px).find("volume 1: sight "), std::string::npos);
  EXPECT_NEAR(shares, 1.0, 1e-5);
  EXPECT_NEAR(blended / px.baked_lux, 1.0, 1e-4);
  EXPECT_FLOAT_EQ(px.spacing, 0.3f);  // the finer volume's
  EXPECT_NE(explain_text(px).find("the error in two"), std::string::npos);
  // Every probe lies inside the box, in front of the wall: none behind it, and no leak line.
  for (const ExplainedProbe& p : px.probes) EXPECT_FALSE(p.behind) << p.weight.probe;
  EXPECT_EQ(explain_text(px).find("behind the surface"), std::string::npos);
}

// The probes past the surface's tangent plane summed: their count, their share of the weight, and
// their share of the baked light (share x baked lux over every listed probe's).
TEST(Explain, ProbesBehindTheSurfaceAreSummedAsALeak) {
  ExplainedPixel px;
  px.hit = true;
  px.normal = {0.f, 1.f, 0.f};
  ExplainedProbe front, behind, unweighed;
  front.share = 0.9f;
  front.baked_lux = 100.0;
  behind.share = 0.1f;
  behind.baked_lux = 1000.0;
  behind.behind = true;
  unweighed.behind = true;  // share 0: not counted
  px.probes = {front, behind, unweighed};
  const BehindSurface b = probes_behind(px);
  EXPECT_EQ(b.probes, 1u);
  EXPECT_NEAR(b.weight, 0.1, 1e-6);
  EXPECT_NEAR(b.light, 100.0 / 190.0, 1e-6);
  const std::string text = explain_text(px);
  EXPECT_NE(text.find("behind the surface: 1 probe past its tangent plane carry 10.0% of the weight and 53% of the "
                      "baked irradiance"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  behind\n"), std::string::npos) << "the probe's row is marked";
  px.probes = {front};
  EXPECT_EQ(explain_text(px).find("behind the surface"), std::string::npos);
}

TEST(Explain, APixelOutsideTheImageIsRefused) {
  Furnace f;
  make_furnace(f);
  ExplainSettings es;
  es.x = 32;  // one past the last column
  es.y = 0;
  ExplainedPixel px;
  const Status st = explain_pixel(*f.prepared, f.two, corner_view(), es, Context{}, px);
  EXPECT_FALSE(st);
  EXPECT_EQ(st.code(), ExitCode::BadArguments);
  EXPECT_NE(st.message().find("outside the 32x32 image"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace gibake
