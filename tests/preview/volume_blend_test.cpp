// Several DDGI volumes read the way an engine blends them (BakeFile::sample_ddgi) by the
// reconstruction check and the preview, against the white furnace: a closed box emitting Le with
// albedo rho, where every wall point's irradiance is the same whatever the probes (ratio 1 against
// the path-traced truth). Two overlapping volumes baked in it, a coarse one over the box (its
// weight on the walls 2/3 per axis: they lie 2/3 of a spacing outside its probes) and a finer one in
// a corner (full weight on the three walls there, its fade band crossing the others), must give that
// constant everywhere: a blend that does not conserve it (weights summing short of 1 where only
// fade bands reach, or added on top of one another) misses by the weights there.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "io/bakefile/bake_file.h"
#include "tests/loader/multi_volume.h"
#include "tests/support/white_furnace.h"

namespace gibake {
namespace {

struct Furnace : test::FurnaceBox {
  loader::BakeFile two, one;  // coarse and fine volumes; the coarse one alone
};

void bake(const Scene& scene, const Vec3f& lo, const Vec3f& hi, int32_t n, DdgiResult& out) {
  const DdgiSettings s = test::furnace_probes(lo, hi, n);
  DdgiReport report;
  ASSERT_TRUE(bake_ddgi(scene, s, Context{}, out, report));
}

void make_furnace(Furnace& f) {
  test::add_furnace_box(f);
  DdgiResult coarse, fine;
  bake(f.scene, {-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f}, 3, coarse);  // spacing 0.6
  bake(f.scene, {-0.9f, -0.9f, -0.9f}, {0.f, 0.f, 0.f}, 4, fine);        // spacing 0.3, fading over (0.15, 0.3)
  const std::string meta = "{\"settings\":" + coarse.settings_json + "}";
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(test::multi_volume_bytes({&coarse, &fine}, BakeFileOptions{}, bytes, meta));
  ASSERT_FALSE(f.two.open(std::move(bytes)));
  ASSERT_TRUE(test::multi_volume_bytes({&coarse}, BakeFileOptions{}, bytes, meta));
  ASSERT_FALSE(f.one.open(std::move(bytes)));
  test::prepare_furnace_box(f);
}

ReconstructionError check(const Furnace& f, const loader::BakeFile& file, const uint32_t* only) {
  // What this measures is the blend of two volumes, not convergence: the reference's paths end
  // where the bake's do, so any ratio off 1 is the blend's.
  const ReconstructionSettings rs = test::furnace_check(48);
  ReconstructionError e;
  EXPECT_TRUE(measure_bake_reconstruction(*f.prepared, f.lod, file, only, rs, Context{}, e));
  return e;
}

TEST(VolumeBlend, FurnaceStaysConstantAcrossTwoVolumes) {
  Furnace f;
  make_furnace(f);
  ASSERT_EQ(f.two.ddgi_volumes().size(), 2u);
  const ReconstructionError e = check(f, f.two, nullptr);
  size_t mixed = 0;  // patches whose first point both volumes weigh
  for (const ReconstructionPatch& p : e.samples) {
    const loader::Vec3 at{p.position[0], p.position[1], p.position[2]};
    mixed += f.two.ddgi_volumes()[0].blend_weight(at) > 0.f && f.two.ddgi_volumes()[1].blend_weight(at) > 0.f;
  }
  std::printf("furnace, two volumes: %u patches (%zu in both volumes), p10 %.4f median %.4f p90 %.4f, indirect "
              "median %.4f\n",
              e.counted, mixed, e.shaded.p10, e.shaded.median, e.shaded.p90, e.indirect.median);
  EXPECT_EQ(e.counted, 48u);
  EXPECT_GT(mixed, 8u);
  // 2%, as the one-volume furnace test: MIS noise of 256 probe rays and 16 x 64 reference paths.
  EXPECT_NEAR(e.shaded.p10, 1.0, 0.02);
  EXPECT_NEAR(e.shaded.median, 1.0, 0.02);
  EXPECT_NEAR(e.shaded.p90, 1.0, 0.02);
  EXPECT_NEAR(e.indirect.median, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(e.shaded.within, 1.0);
  // Only the fine volume (clamped outside its corner): the patches are the fine volume's probes' view.
  const uint32_t fine = 1;
  const ReconstructionError only = check(f, f.two, &fine);
  EXPECT_NE(only.samples[0].position, e.samples[0].position);
}

// One volume: the blended check is that volume's check, patch for patch, to the bit.
TEST(VolumeBlend, OneVolumeCheckIsUnchanged) {
  Furnace f;
  make_furnace(f);
  const uint32_t first = 0;
  const ReconstructionError all = check(f, f.one, nullptr), only = check(f, f.one, &first);
  ASSERT_EQ(all.samples.size(), only.samples.size());
  for (size_t i = 0; i < all.samples.size(); ++i) {
    EXPECT_EQ(all.samples[i].baked, only.samples[i].baked);
    EXPECT_EQ(all.samples[i].reference, only.samples[i].reference);
  }
}

// The preview reads every volume by default, one with `volume`: in the furnace both views are the
// constant, within the probes' noise, and the default one reads the fine volume where it lies.
TEST(VolumeBlend, PreviewReadsEveryVolume) {
  Furnace f;
  make_furnace(f);
  PreviewSettings s;
  s.mode = PreviewMode::Indirect;
  s.width = 64;
  s.height = 48;
  s.camera_given = true;
  s.eye = {0.6f, 0.6f, 0.6f};
  s.target = {-1.f, -1.f, -1.f};  // the corner the fine volume covers
  s.fov_deg = 100.f;
  PreviewImage blended, coarse;
  ASSERT_TRUE(render_preview(*f.prepared, &f.two, s, Context{}, blended));
  s.volume = 0;
  ASSERT_TRUE(render_preview(*f.prepared, &f.two, s, Context{}, coarse));
  s.volume = 2;
  EXPECT_FALSE(render_preview(*f.prepared, &f.two, s, Context{}, coarse).is_ok());
  s.volume = 0;
  ASSERT_TRUE(render_preview(*f.prepared, &f.two, s, Context{}, coarse));
  double mean = 0.0;
  for (float v : coarse.rgb) mean += v;
  mean /= double(coarse.rgb.size());
  size_t differ = 0;
  float worst = 0.f, coarse_worst = 0.f;
  for (size_t i = 0; i < blended.rgb.size(); ++i) {
    differ += blended.rgb[i] != coarse.rgb[i];
    worst = std::max(worst, float(std::fabs(blended.rgb[i] - mean) / mean));
    coarse_worst = std::max(coarse_worst, float(std::fabs(coarse.rgb[i] - mean) / mean));
  }
  std::printf("furnace preview: mean E/pi %.4f; blended within %.4f of it, the coarse volume alone %.4f; %zu of %zu "
              "values read the fine volume\n",
              mean, worst, coarse_worst, differ, blended.rgb.size());
  EXPECT_GT(differ, blended.rgb.size() / 20);
  // 5%: the probes' noise (a few percent for either volume alone); a blend that loses or adds
  // weight in the bands is off by tens of percent there.
  EXPECT_LT(worst, 0.05f);
}

}  // namespace
}  // namespace gibake
