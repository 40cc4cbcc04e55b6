// The reconstruction check against answers known without it: a white furnace, where every surface
// point's irradiance is pi Le sum rho^k whatever the probes' placement (ratio 1, no noise), the
// same bake with its SH scaled (the ratio the scale implies), thread independence, and the block
// comparison on images with a known ratio.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bake/preview/block_compare.h"
#include "bake/preview/check_second_pass.h"
#include "io/bakefile/bake_file.h"
#include "tests/support/white_furnace.h"

namespace gibake {
namespace {

constexpr float kRho = test::kFurnaceRho, kLe = test::kFurnaceLe;
constexpr int kBounces = test::kFurnaceBounces;

// The white furnace (tests/support/white_furnace.h), 3x3x3 probes inside. Both sides carry some
// noise: next-event estimation towards the emissive walls weighs each sample by MIS, which is exact
// only on average.
struct Furnace : test::FurnaceBox {
  DdgiResult result;  // what `file` holds
  loader::BakeFile file;
};

// `r` as a bake file's bytes, opened, with its settings as the bake records them.
void open_as_file(const DdgiResult& r, loader::BakeFile& file) {
  BakeOutputs out;
  out.ddgi = &r;
  out.metadata_json = "{\"settings\":" + r.settings_json + "}";
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(build_bake_file(out, BakeFileOptions{}, bytes));
  ASSERT_FALSE(file.open(std::move(bytes)));
}

// `scale` multiplies every probe's light as the file stores it: its SH and its irradiance atlas.
void make_furnace(Furnace& f, float scale) {
  test::add_furnace_box(f);
  const DdgiSettings s = test::furnace_probes({-0.7f, -0.7f, -0.7f}, {0.7f, 0.7f, 0.7f}, 3);
  DdgiReport report;
  ASSERT_TRUE(bake_ddgi(f.scene, s, Context{}, f.result, report));
  for (float& v : f.result.sh) v *= scale;
  for (size_t i = 0; i < f.result.irradiance_atlas.size(); ++i)
    if (i % 4 != 3) f.result.irradiance_atlas[i] *= scale;  // RGB; alpha stays 1
  open_as_file(f.result, f.file);
  test::prepare_furnace_box(f);
}

ReconstructionError check(const Furnace& f, unsigned threads, uint32_t patches = 24) {
  const ReconstructionSettings rs = test::furnace_check(patches);
  Context ctx;
  ctx.threads = threads;
  ReconstructionError e;
  EXPECT_TRUE(measure_reconstruction(*f.prepared, f.lod, {}, Sky{}, f.file.ddgi_volumes()[0], rs, ctx, e));
  return e;
}

double furnace_sum() {
  double g = 0.0;
  for (int k = 0; k <= kBounces + 1; ++k) g += std::pow(kRho, k);
  return g;
}

TEST(ReconstructionCheck, FurnaceReconstructsExactly) {
  Furnace f;
  make_furnace(f, 1.f);
  const ReconstructionError e = check(f, 0);
  std::printf("furnace: p10 %.4f median %.4f p90 %.4f, indirect median %.4f, reference noise %.4f\n", e.shaded.p10,
              e.shaded.median, e.shaded.p90, e.indirect.median, e.reference_noise);
  EXPECT_EQ(e.patches, 24u);  // every patch lies on a wall seen from a probe
  EXPECT_EQ(e.counted, 24u);
  // Tolerance 2%: the SH and the irradiance atlas of a constant field are exact; what is left is the MIS noise of 256
  // probe rays and of 16 x 64 reference paths a patch, well under 1%.
  EXPECT_NEAR(e.shaded.median, 1.0, 0.02);
  EXPECT_NEAR(e.shaded.p10, 1.0, 0.02);
  EXPECT_NEAR(e.shaded.p90, 1.0, 0.02);
  EXPECT_NEAR(e.indirect.median, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(e.shaded.within, 1.0);
  EXPECT_LT(e.reference_noise, 0.01);
  // The reference itself: shaded luminance per point Le (emission) + rho E / pi = Le sum_{k<=N+2} rho^k.
  const ReconstructionPatch& p = e.samples[0];
  const double expected = kLe * (1.0 + kRho * furnace_sum());
  EXPECT_NEAR(p.reference / p.points, expected, 0.02 * expected);
}

TEST(ReconstructionCheck, ScaledProbesShowTheirScale) {
  Furnace f;
  make_furnace(f, 1.5f);
  const ReconstructionError e = check(f, 0);
  // E baked is 1.5 x E; the shaded radiance Le + rho E / pi gives (1 + 1.5 rho G) / (1 + rho G).
  const double g = furnace_sum(), shaded = (1.0 + 1.5 * kRho * g) / (1.0 + kRho * g);
  EXPECT_NEAR(e.indirect.median, 1.5, 0.045);
  EXPECT_NEAR(e.shaded.median, shaded, 0.04);
  EXPECT_DOUBLE_EQ(e.shaded.within, 0.0);
}

TEST(ReconstructionCheck, SameAnswerForAnyThreadCount) {
  Furnace f;
  make_furnace(f, 1.f);
  const ReconstructionError one = check(f, 1, 8), two = check(f, 2, 8);
  ASSERT_EQ(one.samples.size(), two.samples.size());
  for (size_t i = 0; i < one.samples.size(); ++i) {
    EXPECT_EQ(one.samples[i].reference, two.samples[i].reference);
    EXPECT_EQ(one.samples[i].baked, two.samples[i].baked);
    EXPECT_EQ(one.samples[i].position, two.samples[i].position);
  }
}

// The bake traces the reference beside its file's write, from its results and settings, and reads
// the baked half from the file: the same patches and sums, bit for bit, as measuring the file. The
// probes it starts from (relocated, some inactive) are the loader's to the last bit.
TEST(ReconstructionCheck, ReferenceBeforeTheFileIsTheFileMeasurement) {
  Furnace f;
  make_furnace(f, 1.f);
  DdgiResult moved = f.result;
  for (size_t i = 0; i < moved.offsets.size(); ++i) moved.offsets[i] = 0.0137f * float(int(i % 7) - 3);
  moved.states[4] = ProbeState::Inactive;
  moved.states[11] = ProbeState::SkyOnly;
  loader::BakeFile file;
  open_as_file(moved, file);
  const std::vector<kernels::float3> from_results = active_probe_positions({&moved});
  EXPECT_EQ(from_results.size(), moved.states.size() - 1);
  EXPECT_TRUE(same_positions(from_results, active_probes(file)));

  ReconstructionSettings rs;
  rs.patches = 12;
  rs.rays = 32;
  ReconstructionError whole, halves;
  ASSERT_TRUE(measure_bake_reconstruction(*f.prepared, f.lod, file, nullptr, rs, Context{}, whole));
  ReconstructionReference reference;
  ASSERT_TRUE(trace_bake_reconstruction_reference(*f.prepared, f.lod, moved.settings_json, from_results, rs, Context{},
                                                  reference));
  ASSERT_TRUE(finish_bake_reconstruction(*f.prepared, f.lod, file, reference, rs, Context{}, halves));
  ASSERT_EQ(whole.samples.size(), halves.samples.size());
  ASSERT_GT(whole.samples.size(), 0u);
  for (size_t i = 0; i < whole.samples.size(); ++i) {
    EXPECT_EQ(whole.samples[i].position, halves.samples[i].position) << i;
    EXPECT_EQ(whole.samples[i].points, halves.samples[i].points) << i;
    EXPECT_EQ(whole.samples[i].reference, halves.samples[i].reference) << i;
    EXPECT_EQ(whole.samples[i].baked, halves.samples[i].baked) << i;
    EXPECT_EQ(whole.samples[i].indirect_reference, halves.samples[i].indirect_reference) << i;
    EXPECT_EQ(whole.samples[i].indirect_baked, halves.samples[i].indirect_baked) << i;
  }
  EXPECT_EQ(whole.rays, halves.rays);
  EXPECT_EQ(whole.shaded.median, halves.shaded.median);
}

// A device that fails its trace after half its points: the check warns and traces every path on
// the CPU, with the CPU's sums bit for bit; one whose lighting differs is never asked.
class FailingPathDevice final : public ReferencePathDevice {
 public:
  explicit FailingPathDevice(bool lit) : lit_(lit) {}
  bool lights_match(const std::vector<kernels::ShadeLight>&, const Sky&) const override { return lit_; }
  uint64_t max_paths() const override { return 64 * 32; }  // several blocks of 64 points
  Status trace(const std::vector<ReferencePoint>& points, const ReferencePathParams&,
               std::vector<ReferencePointSums>& out) override {
    ++calls;
    if (calls > 1) return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "device lost");
    out.assign(points.size(), ReferencePointSums{});
    for (ReferencePointSums& o : out) o.sum = kernels::float3{1e6f, 1e6f, 1e6f};  // never kept
    return Status::ok();
  }
  std::string name() const override { return "test device"; }
  int calls = 0;

 private:
  bool lit_;
};

TEST(ReconstructionCheck, FailingDeviceFallsBackToTheCpu) {
  Furnace f;
  make_furnace(f, 1.f);
  ReconstructionSettings rs = test::furnace_check(12);
  rs.rays = 32;
  const std::vector<kernels::float3> probes = active_probes(f.file);
  ReconstructionReference cpu, fallback, unlit;
  ASSERT_TRUE(trace_reconstruction_reference(*f.prepared, f.lod, {}, Sky{}, probes, rs, Context{}, cpu));
  FailingPathDevice failing(true), other_light(false);
  std::vector<std::string> warnings;
  Context ctx;
  ctx.warn = [&](const std::string& m) { warnings.push_back(m); };
  rs.device = &failing;
  ASSERT_TRUE(trace_reconstruction_reference(*f.prepared, f.lod, {}, Sky{}, probes, rs, ctx, fallback));
  EXPECT_EQ(failing.calls, 2);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("device lost"), std::string::npos) << warnings[0];
  EXPECT_TRUE(fallback.device.empty());
  rs.device = &other_light;
  ASSERT_TRUE(trace_reconstruction_reference(*f.prepared, f.lod, {}, Sky{}, probes, rs, Context{}, unlit));
  EXPECT_EQ(other_light.calls, 0);
  ASSERT_EQ(cpu.patches.size(), fallback.patches.size());
  for (size_t i = 0; i < cpu.patches.size(); ++i) {
    EXPECT_EQ(cpu.patches[i].reference, fallback.patches[i].reference) << i;
    EXPECT_EQ(cpu.patches[i].reference_stderr, fallback.patches[i].reference_stderr) << i;
    EXPECT_EQ(cpu.patches[i].reference, unlit.patches[i].reference) << i;
    EXPECT_EQ(cpu.rays[i], fallback.rays[i]) << i;
  }
}

// The second pass: patches noisier than the target get their points traced again with new paths,
// as many as reach the target within the budget. Against the one-pass check of the same patches the
// median noise falls, the furnace's answer stays (the second pass replaces the first: the paths that
// chose the count are not in the estimate) and the sums do not depend on the thread count.
TEST(ReconstructionCheck, NoisyPatchesAreTracedAgainToTheTarget) {
  Furnace f;
  make_furnace(f, 1.f);
  ReconstructionSettings rs = test::furnace_check(24);
  rs.rays = 4;
  rs.target_noise = 0.f;
  const std::vector<kernels::float3> probes = active_probes(f.file);
  ReconstructionError one;
  ASSERT_TRUE(measure_reconstruction(*f.prepared, f.lod, {}, Sky{}, f.file.ddgi_volumes()[0], rs, Context{}, one));
  EXPECT_EQ(one.retraced, 0u);
  ASSERT_GT(one.reference_noise, 0.0);
  // A target of a third of the one-pass noise needs 9 x the paths; a budget of 16 x the first pass lets
  // every patch above it reach it.
  rs.target_noise = float(one.reference_noise / 3.0);
  rs.ray_budget = 16 * rs.rays;
  ReconstructionError two, two_threads;
  ASSERT_TRUE(measure_reconstruction(*f.prepared, f.lod, {}, Sky{}, f.file.ddgi_volumes()[0], rs, Context{}, two));
  Context ctx;
  ctx.threads = 2;
  ASSERT_TRUE(measure_reconstruction(*f.prepared, f.lod, {}, Sky{}, f.file.ddgi_volumes()[0], rs, ctx, two_threads));
  std::printf("one pass: noise %.4f; two passes: noise %.4f, %u patches again, up to %u paths a point\n",
              one.reference_noise, two.reference_noise, two.retraced, two.retraced_rays);
  EXPECT_GE(two.retraced, 12u);  // at least the noisier half
  EXPECT_LE(two.retraced_rays, 64u * rs.rays);
  // The noise of a patch is read from its paths' two halves, itself noisy: the median lands near the
  // target, well under the one-pass noise.
  EXPECT_LT(two.reference_noise, 0.6 * one.reference_noise);
  const double expected = kLe * (1.0 + kRho * furnace_sum());
  ASSERT_EQ(two.samples.size(), one.samples.size());
  for (const ReconstructionPatch& p : two.samples) EXPECT_NEAR(p.reference / p.points, expected, 0.03 * expected);
  EXPECT_NEAR(two.shaded.median, 1.0, 0.02);
  ASSERT_EQ(two.samples.size(), two_threads.samples.size());
  for (size_t i = 0; i < two.samples.size(); ++i) {
    EXPECT_EQ(two.samples[i].reference, two_threads.samples[i].reference) << i;
    EXPECT_EQ(two.samples[i].reference_stderr, two_threads.samples[i].reference_stderr) << i;
  }
  // No budget beyond the first pass: one pass.
  rs.ray_budget = rs.rays;
  ReconstructionError capped;
  ASSERT_TRUE(measure_reconstruction(*f.prepared, f.lod, {}, Sky{}, f.file.ddgi_volumes()[0], rs, Context{}, capped));
  EXPECT_EQ(capped.retraced, 0u);
  EXPECT_EQ(capped.reference_noise, one.reference_noise);
}

// The second pass's counts: with room in the budget every patch above the target reaches it
// (rays x (e / t)^2, at most 64 x rays); with too little, the noisiest patches come to one noise
// above the target and the paths stay within the budget. The CPU's default for camera views lies
// between the probes' view's and a device's.
TEST(ReconstructionCheck, SecondPassCountsReachTheTargetOrOneNoiseWithinTheBudget) {
  // Noises in powers of two, so that the counts are exact: 2, 4 and 8 times the target.
  const std::vector<PatchNoise> patches = {{0.0078125, 16}, {0.015625, 16}, {0.0625, 16}, {0.125, 16}, {0.25, 16}};
  const uint32_t rays = 128;
  const float target = 0.03125f;
  EXPECT_EQ(second_pass_rays(patches, rays, target, 64 * rays, kCpuBudgetFactor),
            (std::vector<uint32_t>{0, 0, 512, 2048, 8192}));
  EXPECT_EQ(default_budget_factor(true, false), kDeviceBudgetFactor);
  EXPECT_EQ(default_budget_factor(true, true), kDeviceBudgetFactor);
  EXPECT_EQ(default_budget_factor(false, false), kCpuBudgetFactor);
  EXPECT_EQ(default_budget_factor(false, true), kCpuViewBudgetFactor);
  // The default budgets: a device's is large enough here, the CPU's is not.
  EXPECT_EQ(second_pass_rays(patches, rays, target, 0, kDeviceBudgetFactor),
            (std::vector<uint32_t>{0, 0, 512, 2048, 8192}));
  const std::vector<uint32_t> tight = second_pass_rays(patches, rays, target, 0, kCpuBudgetFactor);
  const double extra = 5.0 * 16 * (kCpuBudgetFactor - 1) * rays;
  double spent = 0.0, level = 0.0;
  for (size_t i = 0; i < patches.size(); ++i) {
    spent += 16.0 * tight[i];
    if (tight[i] == 0) continue;
    const double reached = patches[i].noise * std::sqrt(double(rays) / tight[i]);
    if (level == 0.0) level = reached;
    EXPECT_NEAR(reached, level, 0.01 * level) << i;  // one noise, up to the rounding of a count
  }
  EXPECT_LE(spent, extra);
  EXPECT_GT(spent, 0.9 * extra);
  EXPECT_GT(level, patches[2].noise);  // the third patch, above the target, is left: the level is above it
  EXPECT_EQ(tight[0] + tight[1] + tight[2], 0u);
  // A camera view's CPU budget: every patch the probes' view left gets more, none past a device's.
  const std::vector<uint32_t> view = second_pass_rays(patches, rays, target, 0, kCpuViewBudgetFactor);
  double view_spent = 0.0;
  for (size_t i = 0; i < patches.size(); ++i) {
    EXPECT_GE(view[i], tight[i]) << i;
    EXPECT_LE(view[i], (std::vector<uint32_t>{0, 0, 512, 2048, 8192})[i]) << i;
    view_spent += 16.0 * view[i];
  }
  EXPECT_LE(view_spent, 5.0 * 16 * (kCpuViewBudgetFactor - 1) * rays);
  EXPECT_GT(view[3], tight[3]);
  EXPECT_EQ(second_pass_rays(patches, rays, 0.f, 0, kDeviceBudgetFactor), std::vector<uint32_t>(5, 0));  // off
  EXPECT_EQ(second_pass_rays(patches, rays, target, rays, kDeviceBudgetFactor),
            std::vector<uint32_t>(5, 0));  // no budget
}

TEST(ReconstructionCheck, BlockComparisonOfKnownRatios) {
  PreviewImage ref, test;
  ref.width = test.width = 32;
  ref.height = test.height = 16;  // 4 x 2 blocks of 8x8
  ref.rgb.assign(32 * 16 * 3, 1.f);
  test.rgb.assign(32 * 16 * 3, 1.f);
  // Block column c gets ratio 1.0, 1.05, 1.2, 1.3 in both block rows.
  const float ratio[4] = {1.f, 1.05f, 1.2f, 1.3f};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      for (int k = 0; k < 3; ++k) test.rgb[(size_t(y) * 32 + x) * 3 + k] = ratio[x / 8];
  BlockComparison b;
  ASSERT_TRUE(compare_blocks(test, ref, 8, 0.10f, 0.001f, b));
  EXPECT_EQ(b.blocks, 8u);
  EXPECT_DOUBLE_EQ(b.ratio.within, 0.5);  // 1.0 and 1.05
  EXPECT_NEAR(b.ratio.p10, 1.0, 1e-6);
  EXPECT_NEAR(b.ratio.p90, 1.3, 1e-6);
  PreviewImage small = ref;
  small.width = 8;
  EXPECT_FALSE(compare_blocks(test, small, 8, 0.1f, 0.f, b));
}

// Blocks of known ratios: each block's ratio in row order (not counted where the reference is black), the
// blocks farthest off by |log ratio| (twice and half equally far), and the map's colours: grey within 10%,
// red where the lit view is brighter, blue where darker, dimmed where not counted.
TEST(ReconstructionCheck, BlockRatiosWorstBlocksAndTheirMap) {
  PreviewImage ref, test;
  ref.width = test.width = 36;  // 4 whole blocks a row and a partial column of 4 pixels
  ref.height = test.height = 16;
  ref.rgb.assign(36 * 16 * 3, 1.f);
  test.rgb.assign(36 * 16 * 3, 1.f);
  const float ratio[2][4] = {{1.f, 1.05f, 2.5f, 0.5f}, {1.f, 1.f, 1.f, 0.8f}};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      for (int k = 0; k < 3; ++k) {
        test.rgb[(size_t(y) * 36 + x) * 3 + k] = ratio[y / 8][x / 8];
        if (y >= 8 && x >= 8 && x < 16) ref.rgb[(size_t(y) * 36 + x) * 3 + k] = 0.f;  // block (1, 1): black
      }
  BlockRatios r;
  ASSERT_TRUE(block_ratios(test, ref, 8, 0.001f, r));
  ASSERT_EQ(r.columns, 4);
  ASSERT_EQ(r.rows, 2);
  ASSERT_EQ(r.ratio.size(), 8u);
  EXPECT_NEAR(r.ratio[2], 2.5, 1e-6);
  EXPECT_NEAR(r.ratio[3], 0.5, 1e-6);
  EXPECT_TRUE(std::isnan(r.ratio[5]));
  const std::vector<BlockAt> worst = worst_blocks(r, 0.10f, 5);
  ASSERT_EQ(worst.size(), 3u);  // 2.5, 0.5, 0.8: the others are within 10% or not counted
  EXPECT_EQ(worst[0].x, 20);
  EXPECT_EQ(worst[0].y, 4);
  EXPECT_NEAR(worst[0].ratio, 2.5, 1e-6);
  EXPECT_EQ(worst[1].x, 28);
  EXPECT_EQ(worst[1].y, 4);
  EXPECT_EQ(worst[2].x, 28);
  EXPECT_EQ(worst[2].y, 12);
  EXPECT_EQ(worst_blocks(r, 0.10f, 1).size(), 1u);
  const std::vector<uint8_t> map = block_map_rgb8(ref, r, 0.10f);
  ASSERT_EQ(map.size(), ref.rgb.size());
  auto px = [&](int x, int y) { return &map[(size_t(y) * 36 + x) * 3]; };
  const uint8_t* grey = px(4, 4);  // ratio 1
  EXPECT_EQ(grey[0], grey[1]);
  EXPECT_EQ(grey[1], grey[2]);
  EXPECT_GT(grey[0], 40);
  EXPECT_EQ(px(12, 4)[0], grey[0]) << "1.05 is within 10%";
  EXPECT_GT(px(20, 4)[0], px(20, 4)[2] + 100) << "brighter: red";
  EXPECT_GT(px(28, 4)[2], px(28, 4)[0] + 100) << "darker: blue";
  EXPECT_GT(px(28, 4)[2] - px(28, 4)[0], px(28, 12)[2] - px(28, 12)[0]) << "half is bluer than 0.8";
  EXPECT_LT(px(34, 4)[0], grey[0]) << "the partial column is not counted: dimmed";
  const uint8_t* black = px(12, 12);
  EXPECT_EQ(black[0], 0) << "a black reference stays black";
  // A block whose lit view is not a number is counted, listed first and drawn red, not left out.
  test.rgb[(size_t(4) * 36 + 12) * 3] = std::nanf("");
  ASSERT_TRUE(block_ratios(test, ref, 8, 0.001f, r));
  EXPECT_TRUE(r.counted[1]);
  EXPECT_TRUE(std::isnan(r.ratio[1]));
  EXPECT_EQ(worst_blocks(r, 0.10f, 5).front().x, 12);
  const std::vector<uint8_t> with_nan = block_map_rgb8(ref, r, 0.10f);
  EXPECT_GT(with_nan[(size_t(4) * 36 + 12) * 3], with_nan[(size_t(4) * 36 + 12) * 3 + 2] + 100);
  BlockComparison b;
  ASSERT_TRUE(compare_blocks(test, ref, 8, 0.10f, 0.001f, b));
  EXPECT_EQ(b.blocks, 7u) << "every block but the black one";
}

// Halves of known means: 4 samples a pixel, first half 1 + d, full 1, so the second half is 1 - d and
// the full mean's error scale is |A - B| sqrt(2 x 2) / 4 = d.
TEST(ReconstructionCheck, ReferenceNoiseOfKnownHalves) {
  PreviewImage ref;
  ref.width = 32;
  ref.height = 16;
  ref.spp = 4;
  ref.rgb.assign(32 * 16 * 3, 1.f);
  ref.first_half_rgb.assign(ref.rgb.size(), 1.f);
  const float d[4] = {0.f, 0.05f, 0.15f, 0.3f};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      for (int k = 0; k < 3; ++k) ref.first_half_rgb[(size_t(y) * 32 + x) * 3 + k] = 1.f + d[x / 8];
  ReferenceNoise noise;
  ASSERT_TRUE(reference_noise(ref, 8, 0.10f, 0.001f, noise));
  EXPECT_EQ(noise.blocks, 8u);
  EXPECT_DOUBLE_EQ(noise.within, 0.5);  // d = 0 and 0.05
  EXPECT_NEAR(noise.median_error, 0.15, 1e-5);
  ref.first_half_rgb.clear();
  EXPECT_FALSE(reference_noise(ref, 8, 0.10f, 0.001f, noise));
}

}  // namespace
}  // namespace gibake
