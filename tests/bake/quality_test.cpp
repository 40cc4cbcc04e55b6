// The quality levels' presets (bake/ddgi/quality.h): the words, the values each level documents,
// the default level equal to the library's own grid rule, and the spacing rule doubled (draft) or
// halved (final) on boxes where no bound or budget binds.
#include "bake/ddgi/quality.h"

#include <gtest/gtest.h>

#include <limits>

#include "bake/ddgi/ddgi.h"

namespace gibake {
namespace {

TEST(QualityLevels, WordsParseAndNothingElse) {
  Quality q = Quality::Default;
  ASSERT_TRUE(parse_quality("draft", q));
  EXPECT_EQ(q, Quality::Draft);
  ASSERT_TRUE(parse_quality("final", q));
  EXPECT_EQ(q, Quality::Final);
  ASSERT_TRUE(parse_quality("default", q));
  EXPECT_EQ(q, Quality::Default);
  for (const char* bad : {"", "Draft", "finale", "high", "default "}) EXPECT_FALSE(parse_quality(bad, q)) << bad;
  for (const std::string& name : quality_names()) ASSERT_TRUE(parse_quality(name, q)) << name;
}

TEST(QualityLevels, EachLevelSetsItsDocumentedValues) {
  struct Want {
    Quality q;
    int32_t cells;
    float min_spacing, max_spacing;
    uint64_t budget;
    uint32_t rays, max_rays, ray_budget;
  };
  for (const Want& w : {Want{Quality::Draft, 12, 0.5f, 2.f, 4096, 256, 1024, 512},
                        Want{Quality::Default, 24, 0.25f, 1.f, 32768, 512, 0, 1024},
                        Want{Quality::Final, 48, 0.125f, 0.5f, 131072, 512, 16384, 6144}}) {
    DdgiSettings s;
    s.gather = Gather::Path;
    apply_quality(w.q, s);
    EXPECT_EQ(s.grid.auto_cells, w.cells) << quality_name(w.q);
    EXPECT_EQ(s.grid.auto_min_spacing, w.min_spacing) << quality_name(w.q);
    EXPECT_EQ(s.grid.auto_max_spacing, w.max_spacing) << quality_name(w.q);
    EXPECT_EQ(s.grid.auto_max_probes, w.budget) << quality_name(w.q);
    EXPECT_EQ(s.rays, w.rays) << quality_name(w.q);
    EXPECT_EQ(s.max_rays, w.max_rays) << quality_name(w.q);
    EXPECT_EQ(s.ray_budget, w.ray_budget) << quality_name(w.q);
    EXPECT_EQ(s.target_error, 0.05f) << quality_name(w.q);
    EXPECT_EQ(s.bounces, kPathGatherBounces) << quality_name(w.q);  // roulette-ended in every level
    EXPECT_TRUE(s.irradiance_atlas) << quality_name(w.q);           // the samplers read it
    EXPECT_EQ(s.depth_tile, w.q == Quality::Final ? 8 : kDepthTexels) << quality_name(w.q);
    EXPECT_EQ(s.filter.enabled, w.q == Quality::Draft) << quality_name(w.q);  // no fit, few rays: filtered
    // Every level's fit paths are also ended in the probes' light (quality.cpp says why).
    EXPECT_EQ(s.fit.gather, FitGather::Both) << quality_name(w.q);
    // Points found by 64 rays a probe at every level that fits: points count for more than paths.
    EXPECT_EQ(s.fit.directions, 64u) << quality_name(w.q);
    // The default's fit paths may be ended by roulette from their first hit, so that more of them
    // fit its time; final's from the third, as the reference's paths (the documented values).
    EXPECT_EQ(s.fit.paths, w.q == Quality::Final ? 384u : 144u) << quality_name(w.q);
    EXPECT_EQ(s.fit.roulette_depth, w.q == Quality::Final ? 3 : 1) << quality_name(w.q);
    // The default's fit is solved again relative to its own light; final's once (quality.cpp says why).
    EXPECT_EQ(s.fit.relative_to_fit, w.q == Quality::Final ? 0.f : 0.5f) << quality_name(w.q);
    // The default's fit ends its paths in probes fitted to the whole paths; final's in the baked
    // probes, in one pass (quality.cpp says why).
    EXPECT_EQ(s.fit.passes, w.q == Quality::Final ? 1u : 2u) << quality_name(w.q);
    s.gather = Gather::Probes;
    apply_quality(w.q, s);
    EXPECT_EQ(s.bounces, kProbeGatherBounces) << quality_name(w.q);
  }
}

// The fit's second solve weighs residuals by the fitted light to a power within [0, 1]: the
// settings check refuses others, and the file records the power.
TEST(QualityLevels, TheFitsResidualPowerIsCheckedAndRecorded) {
  DdgiSettings s;
  apply_quality(Quality::Default, s);
  for (float power : {0.f, 0.5f, 1.f}) {
    s.fit.relative_to_fit = power;
    EXPECT_TRUE(validate_ddgi_settings(s).is_ok()) << power;
  }
  for (float power : {-0.1f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
    s.fit.relative_to_fit = power;
    EXPECT_FALSE(validate_ddgi_settings(s).is_ok()) << power;
  }
  s.fit.relative_to_fit = 0.5f;
  EXPECT_NE(ddgi_settings_json(s).find("\"relative_to_fit\":0.5"), std::string::npos) << ddgi_settings_json(s);
}

TEST(QualityLevels, DefaultLevelIsTheLibrarysGridRule) {
  DdgiSettings s;
  apply_quality(Quality::Default, s);
  const GridSettings rule;
  EXPECT_EQ(s.grid.auto_cells, rule.auto_cells);
  EXPECT_EQ(s.grid.auto_min_cells, rule.auto_min_cells);
  EXPECT_EQ(s.grid.auto_min_spacing, rule.auto_min_spacing);
  EXPECT_EQ(s.grid.auto_max_spacing, rule.auto_max_spacing);
  EXPECT_EQ(s.grid.auto_max_probes, rule.auto_max_probes);
  EXPECT_EQ(s.fit.gather, SurfaceFitSettings{}.gather);
}

TEST(QualityLevels, DraftDoublesAndFinalHalvesTheSpacing) {
  // Boxes where each part of the rule decides: 10 m (longest / cells, 0.417 m), 2 m (the 0.25 m
  // floor), 1 m (the small-model floor, longest / min cells), 48 m (the 1 m cap).
  for (const std::array<float, 3>& box : {std::array<float, 3>{10.f, 5.f, 8.f}, std::array<float, 3>{2.f, 2.f, 2.f},
                                          std::array<float, 3>{1.f, 0.5f, 0.5f}, std::array<float, 3>{48.f, 20.f, 10.f}}) {
    DdgiSettings d, n, f;
    apply_quality(Quality::Draft, d);
    apply_quality(Quality::Default, n);
    apply_quality(Quality::Final, f);
    const float normal = default_probe_spacing(box, n.grid);
    EXPECT_FLOAT_EQ(default_probe_spacing(box, d.grid), 2.f * normal) << box[0];
    EXPECT_FLOAT_EQ(default_probe_spacing(box, f.grid), 0.5f * normal) << box[0];
  }
}

TEST(QualityLevels, TheSummaryLineSaysWhatWasChosenAndWhatWasGiven) {
  DdgiSettings s;
  apply_quality(Quality::Final, s);
  s.rays = 64;
  EXPECT_EQ(quality_text(Quality::Final, s, 0.5f, {"--rays"}),
            "quality final: spacing 0.5 m (longest side / 48 within 0.125-0.5 m, at least 16 cells across, at most "
            "131072 probes), rays "
            "64-16384, ray budget 6144, bounces until roulette ends them, probe filter off, surface fit on (1048576 "
            "points found by 64 rays a probe, 384 paths each, roulette from hit 3, also ended in the probes' light), "
            "depth tiles 8x8; given explicitly: --rays");
  s.target_error = 0.f;
  s.bounces = 3;
  EXPECT_EQ(quality_text(Quality::Final, s, 0.f, {}),
            "quality final: spacing (longest side / 48 within 0.125-0.5 m, at least 16 cells across, at most 131072 "
            "probes), rays 64, bounces 3, "
            "probe filter off, surface fit on (1048576 points found by 64 rays a probe, 384 paths each, roulette from "
            "hit 3, also ended in the probes' light), depth "
            "tiles 8x8");
  s.irradiance_atlas = false;  // --irradiance-atlas off is said; --depth-tile 16 over the level is not
  s.depth_tile = kDepthTexels;
  EXPECT_EQ(
      quality_text(Quality::Final, s, 0.f, {"--irradiance-atlas", "--depth-tile"}),
      "quality final: spacing (longest side / 48 within 0.125-0.5 m, at least 16 cells across, at most 131072 probes), "
      "rays 64, bounces 3, "
      "no irradiance atlas, probe filter off, surface fit off; given explicitly: --irradiance-atlas, --depth-tile");
  s.irradiance_atlas = true;
  s.depth_tile = kDepthTexels;
  EXPECT_EQ(quality_text(Quality::Final, s, 0.f, {"--irradiance-atlas", "--depth-tile"}),
            "quality final: spacing (longest side / 48 within 0.125-0.5 m, at least 16 cells across, at most 131072 "
            "probes), rays 64, bounces 3, "
            "probe filter off, surface fit on (1048576 points found by 64 rays a probe, 384 paths each, roulette from "
            "hit 3, also ended in the probes' light); given "
            "explicitly: --irradiance-atlas, "
            "--depth-tile");
  s.filter.enabled = true;  // --probe-filter on over final
  EXPECT_EQ(quality_text(Quality::Final, s, 0.f, {"--probe-filter"}),
            "quality final: spacing (longest side / 48 within 0.125-0.5 m, at least 16 cells across, at most 131072 "
            "probes), rays 64, bounces 3, "
            "probe filter on, surface fit on (1048576 points found by 64 rays a probe, 384 paths each, roulette from "
            "hit 3, also ended in the probes' light); given "
            "explicitly: --probe-filter");
  s.fit.enabled = false;  // --surface-fit off over final
  EXPECT_EQ(quality_text(Quality::Final, s, 0.f, {"--probe-filter", "--surface-fit"}),
            "quality final: spacing (longest side / 48 within 0.125-0.5 m, at least 16 cells across, at most 131072 "
            "probes), rays 64, bounces 3, "
            "probe filter on, surface fit off; given explicitly: --probe-filter, --surface-fit");
}

}  // namespace
}  // namespace gibake
