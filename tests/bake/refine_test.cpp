// Adaptive refinement (bake/ddgi/refine.h). Known by construction: a 12 m ground lit by a sun
// straight down, half of it under an opaque roof 3 m up. The direct light on the ground changes only
// along the roof's edge (x = 0), and across the roof slab (lit on top, dark beneath); it is uniform
// on the open ground, under the roof away from its edge and in the air. So the bricks the rule
// refines must hold the edge or the slab, and none may lie on the uniform ground or in mid-air.
#include "bake/ddgi/refine.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bake/ddgi/volume_plan.h"
#include "bake/pipeline/devices.h"
#include "bake/run/run_context.h"
#include "bake/scene/lights.h"
#include "scene_builders.h"

namespace {

using gibake::RefineDecision;
using gibake::RefineSettings;
using gibake::Scene;

// The ground (y = 0, 12 x 12 m) and the roof slab over x < 0 (y 3 to 3.1).
Scene half_roofed_ground() {
  Scene s;
  const int m = gibake::test::add_material(s, 0.5f);
  gibake::test::add_quad(s, {-6, 0, -6}, {6, 0, -6}, {6, 0, 6}, {-6, 0, 6}, {0, 1, 0}, m);
  gibake::test::add_box(s, {-6.f, 3.f, -6.f}, {0.f, 3.1f, 6.f}, false, m);
  return s;
}

gibake::DdgiSettings sun_settings(bool sun = true) {
  gibake::DdgiSettings s;
  if (sun) s.suns.push_back(gibake::SunLight{{0.f, -1.f, 0.f}, 50000.f, {1.f, 1.f, 1.f}});
  return s;
}

bool inside(const gibake::RefinedBox& b, float x, float y, float z) {
  return x >= b.lo[0] && x <= b.hi[0] && y >= b.lo[1] && y <= b.hi[1] && z >= b.lo[2] && z <= b.hi[2];
}

bool any_inside(const RefineDecision& d, float x, float y, float z) {
  return std::any_of(d.boxes.begin(), d.boxes.end(), [&](const gibake::RefinedBox& b) { return inside(b, x, y, z); });
}

RefineDecision plan_refinement(const Scene& scene, const gibake::DdgiSettings& s, const RefineSettings& r,
                               gibake::VolumePlan* out = nullptr, unsigned threads = 0) {
  gibake::VolumeSettings vs;
  vs.refine = r;
  gibake::Context ctx;
  ctx.threads = threads;
  gibake::VolumePlan plan;
  EXPECT_TRUE(gibake::plan_ddgi_volumes(scene, s, vs, ctx, plan).is_ok());
  RefineDecision d;
  d.text = plan.refine_text;
  for (const gibake::PlannedVolume& v : plan.volumes) {
    if (v.kind != gibake::VolumeKind::Refined) continue;
    gibake::RefinedBox b;
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = v.placed.desc.grid_min[a] - 0.5f * v.placed.desc.spacing[a];
      b.hi[a] = v.placed.desc.grid_max[a] + 0.5f * v.placed.desc.spacing[a];
    }
    d.boxes.push_back(b);
    d.probes += uint64_t(v.placed.desc.probe_count());
  }
  if (out) *out = std::move(plan);
  return d;
}

RefineSettings changing_only(uint64_t budget) {
  RefineSettings r;
  r.budget = budget;
  r.rings = 0;
  return r;
}

TEST(Refinement, RefinesTheSunlitEdgeAndTheSlabNotTheUniformGroundOrTheAir) {
  const Scene scene = half_roofed_ground();
  gibake::VolumePlan plan;
  const RefineDecision d = plan_refinement(scene, sun_settings(), changing_only(1 << 20), &plan);
  ASSERT_FALSE(d.boxes.empty()) << d.text;
  const float spacing = gibake::min_cell_size(plan.volumes[0].placed.desc);
  for (const gibake::PlannedVolume& v : plan.volumes) {
    if (v.kind == gibake::VolumeKind::Refined) {
      EXPECT_FLOAT_EQ(gibake::min_cell_size(v.placed.desc), spacing / 2);
    }
  }
  // The edge on the ground and the slab are refined along their whole length.
  for (float z : {-4.5f, 0.1f, 4.5f}) {
    EXPECT_TRUE(any_inside(d, 0.05f, 0.05f, z)) << "edge at z " << z << "; " << d.text;
    EXPECT_TRUE(any_inside(d, -3.f, 3.05f, z)) << "slab at z " << z;
  }
  // Uniform light: the open ground, the shaded ground away from the edge, the air between.
  for (float z : {-4.5f, 0.1f, 4.5f}) {
    EXPECT_FALSE(any_inside(d, 4.f, 0.05f, z)) << "lit ground at z " << z;
    EXPECT_FALSE(any_inside(d, -4.f, 0.05f, z)) << "shaded ground at z " << z;
    EXPECT_FALSE(any_inside(d, 3.f, 1.5f, z)) << "air at z " << z;
  }
  EXPECT_NE(d.text.find("where the direct light changes"), std::string::npos) << d.text;
}

TEST(Refinement, RingsFollowTheEdgeOverNearbySurfacesWithinTheBudget) {
  const Scene scene = half_roofed_ground();
  RefineSettings r = changing_only(1 << 20);
  r.rings = 2;
  const RefineDecision d = plan_refinement(scene, sun_settings(), r);
  // Two bricks (of 1 m: the default grid's 0.5 m cells, two a side) out from the edge, on the ground.
  EXPECT_TRUE(any_inside(d, 1.5f, 0.05f, 0.1f)) << d.text;
  EXPECT_TRUE(any_inside(d, -1.5f, 0.05f, 0.1f)) << d.text;
  EXPECT_FALSE(any_inside(d, 4.5f, 0.05f, 0.1f)) << d.text;
  // A budget smaller than the whole is kept, and so is a cap on the volumes.
  for (uint64_t budget : {300u, 2000u}) {
    r.budget = budget;
    r.max_volumes = 3;
    const RefineDecision small = plan_refinement(scene, sun_settings(), r);
    EXPECT_LE(small.probes, budget) << small.text;
    EXPECT_LE(small.boxes.size(), 3u) << small.text;
    EXPECT_GT(small.probes, 0u) << small.text;
  }
}

// The edge's bricks under the roof and the slab's top have the same contrast (lit at 50,000 lux
// against the dark), but the slab lies under open sky: within a budget for about the edge alone,
// the covered side of the edge is refined along its whole length and the slab is not.
TEST(Refinement, BricksUnderCoverRankBeforeBricksUnderOpenSky) {
  const Scene scene = half_roofed_ground();
  const RefineDecision d = plan_refinement(scene, sun_settings(), changing_only(1200));
  for (float z : {-4.5f, 0.1f, 4.5f}) {
    EXPECT_TRUE(any_inside(d, -0.05f, 0.05f, z)) << "covered edge at z " << z << "; " << d.text;
    EXPECT_FALSE(any_inside(d, -3.f, 3.05f, z)) << "slab under open sky at z " << z << "; " << d.text;
  }
  EXPECT_NE(d.text.find("under cover; under open sky a brick counts a tenth"), std::string::npos) << d.text;
}

TEST(Refinement, SameBoxesForAnyThreadCount) {
  const Scene scene = half_roofed_ground();
  RefineSettings r = changing_only(6000);
  r.rings = 3;
  const RefineDecision one = plan_refinement(scene, sun_settings(), r, nullptr, 1);
  const RefineDecision two = plan_refinement(scene, sun_settings(), r, nullptr, 2);
  ASSERT_FALSE(one.boxes.empty());
  ASSERT_EQ(one.boxes.size(), two.boxes.size());
  for (size_t i = 0; i < one.boxes.size(); ++i) {
    EXPECT_EQ(one.boxes[i].lo, two.boxes[i].lo);
    EXPECT_EQ(one.boxes[i].hi, two.boxes[i].hi);
  }
  EXPECT_EQ(one.text, two.text);
}

TEST(Refinement, NoneWithoutADirectionalOrPositionedLightOrWhenNotAskedFor) {
  const Scene scene = half_roofed_ground();
  const RefineDecision sky_only = plan_refinement(scene, sun_settings(false), changing_only(1 << 20));
  EXPECT_TRUE(sky_only.boxes.empty());
  EXPECT_NE(sky_only.text.find("refinement: none"), std::string::npos) << sky_only.text;
  const RefineDecision off = plan_refinement(scene, sun_settings(), changing_only(0));
  EXPECT_TRUE(off.boxes.empty());
  EXPECT_TRUE(off.text.empty());
}

// Refined volumes bake with the refinement's ray budget (RefineSettings::ray_budget), a first batch
// of half of it, and every other volume with the bake's rays: the settings each volume is given,
// and the rays its probes were traced with (a budget is an average over a volume's probes).
TEST(Refinement, RefinedVolumesTraceWithinTheirOwnRayBudget) {
  const Scene scene = half_roofed_ground();
  gibake::DdgiSettings s = sun_settings();
  s.rays = 128;
  s.target_error = 0.01f;  // below what these budgets reach: the budgets decide
  s.ray_budget = 512;
  s.grid.auto_max_probes = 400;
  RefineSettings r = changing_only(600);
  r.ray_budget = 128;
  gibake::VolumeSettings vs;
  vs.refine = r;
  gibake::Context ctx;
  const gibake::PipelineDevices platform;
  gibake::RunContext run;
  run.platform = &platform;
  std::vector<gibake::BakedVolume> baked;
  const gibake::Status st = gibake::bake_ddgi_volumes(scene, s, vs, run, ctx, baked);
  ASSERT_TRUE(st.is_ok()) << st.message();
  ASSERT_GE(baked.size(), 2u);
  for (const gibake::BakedVolume& v : baked) {
    ASSERT_GT(v.report.active, 0) << v.why;
    const double per_probe = double(v.report.primary_rays) / v.report.active;
    if (v.kind == gibake::VolumeKind::Refined)
      EXPECT_LE(per_probe, 128.0 * 1.01) << v.why;
    else
      EXPECT_GT(per_probe, 2.0 * 128.0) << v.why;
  }
  gibake::PlannedVolume refined;
  refined.ray_budget = 128;
  const gibake::DdgiSettings adaptive = gibake::planned_volume_settings(s, refined);
  EXPECT_EQ(adaptive.rays, 64u);
  EXPECT_EQ(adaptive.ray_budget, 128u);
  refined.ray_budget = 4096;  // never more than the bake's own budget
  EXPECT_EQ(gibake::planned_volume_settings(s, refined).ray_budget, 512u);
  s.target_error = 0.f;  // fixed rays: that many a probe, at most --rays
  refined.ray_budget = 100;
  EXPECT_EQ(gibake::planned_volume_settings(s, refined).rays, 100u);
  refined.ray_budget = 0;  // none of its own: the bake's
  EXPECT_EQ(gibake::planned_volume_settings(s, refined).rays, 128u);
}

// A bake runs the refinement beside its first volume (plan_ddgi_volumes without it, then
// plan_refinement): the same volumes as planned in one go, and one miss depth for all of them,
// known before the refinement ran. The depth covers the default grid's cell box, which holds every
// refined grid.
TEST(Refinement, PlannedLaterTheSameVolumesWithOneMissDepth) {
  const Scene scene = half_roofed_ground();
  const gibake::DdgiSettings s = sun_settings();
  gibake::VolumeSettings vs;
  vs.refine = changing_only(4096);
  gibake::VolumePlan whole, first;
  ASSERT_TRUE(gibake::plan_ddgi_volumes(scene, s, vs, gibake::Context{}, whole));
  ASSERT_TRUE(gibake::plan_ddgi_volumes(scene, s, vs, gibake::Context{}, first, nullptr, false));
  ASSERT_EQ(first.volumes.size(), 1u);  // the default grid alone
  EXPECT_TRUE(first.refine_text.empty());
  const float depth = first.volumes[0].placed.desc.max_distance;
  ASSERT_TRUE(gibake::plan_refinement(scene, s, vs, gibake::Context{}, first));
  ASSERT_GE(whole.volumes.size(), 3u);  // the grid and refined volumes on both sides of the edge
  ASSERT_EQ(first.volumes.size(), whole.volumes.size());
  EXPECT_EQ(first.refine_text, whole.refine_text);
  const gibake::DdgiVolumeDesc& grid = whole.volumes[0].placed.desc;
  for (size_t i = 0; i < whole.volumes.size(); ++i) {
    const gibake::DdgiVolumeDesc &a = whole.volumes[i].placed.desc, &b = first.volumes[i].placed.desc;
    EXPECT_EQ(whole.volumes[i].kind, first.volumes[i].kind) << i;
    EXPECT_EQ(a.counts, b.counts) << i;
    EXPECT_EQ(a.grid_min, b.grid_min) << i;
    EXPECT_EQ(a.grid_max, b.grid_max) << i;
    EXPECT_EQ(a.max_distance, depth) << i;
    EXPECT_EQ(b.max_distance, depth) << i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(a.grid_min[k], grid.grid_min[k] - 0.5f * grid.spacing[k]) << i;
      EXPECT_LE(a.grid_max[k], grid.grid_max[k] + 0.5f * grid.spacing[k]) << i;
    }
    // A miss reads farther than any surface a probe of the volume could hit: farther than the
    // farthest corner of the scene from any corner of its grid.
    for (int c = 0; c < 8; ++c)
      for (int e = 0; e < 8; ++e) {
        float d2 = 0.f;
        for (int k = 0; k < 3; ++k) {
          const float p = (c >> k) & 1 ? a.grid_max[k] : a.grid_min[k];
          const float q = (e >> k) & 1 ? scene.bounds.max[k] : scene.bounds.min[k];
          d2 += (p - q) * (p - q);
        }
        EXPECT_GT(depth, std::sqrt(d2)) << i;
      }
  }
}

}  // namespace
