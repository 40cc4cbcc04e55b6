// Preview properties with independent answers (no golden images).
#include "bake/preview/preview.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/preview/block_compare.h"
#include "bake/preview/reconstruction_check.h"
#include "io/bakefile/bake_file.h"
#include "io/gltf/import.h"
#include "tests/bake/scene_builders.h"
#include "tests/support/cli_run.h"
#include "tests/support/probe_grid.h"

namespace gibake {
namespace {

Status bake_to_file(const Scene& scene, DdgiSettings s, loader::BakeFile& file) {
  DdgiResult result;
  DdgiReport report;
  s.cgal_check = false;
  GIBAKE_TRY(bake_ddgi(scene, s, Context{}, result, report));
  BakeOutputs out;
  out.ddgi = &result;
  out.metadata_json = "{\"settings\":" + result.settings_json + "}";
  std::vector<uint8_t> bytes;
  GIBAKE_TRY(build_bake_file(out, BakeFileOptions{}, bytes));
  if (loader::Error e = file.open(std::move(bytes)); e) return Status::invalid("", "", e.message);
  return Status::ok();
}

float lum(const PreviewImage& img, int x, int y) {
  const float* c = &img.rgb[(size_t(y) * img.width + x) * 3];
  return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

bool all_finite(const PreviewImage& img) {
  for (float v : img.rgb)
    if (!std::isfinite(v)) return false;
  return true;
}

// A 20 m square plane at y = 0, albedo rho, lit by a sun straight down (E lux), black sky.
Scene sunlit_plane(float rho) {
  Scene s;
  const int m = test::add_material(s, rho);
  test::add_quad(s, {-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}, {0, 1, 0}, m);
  return s;
}

PreviewSettings look_down(PreviewMode mode) {
  PreviewSettings ps;
  ps.mode = mode;
  ps.width = ps.height = 32;
  ps.camera_given = true;
  ps.eye = {0.f, 5.f, 0.f};
  ps.target = {0.f, 0.f, 0.f};
  ps.up = {0.f, 0.f, -1.f};
  ps.fov_deg = 40.f;
  return ps;
}

TEST(Preview, AlbedoModeRendersTheExactAlbedo) {
  const Scene s = sunlit_plane(0.37f);
  PreviewImage img;
  ASSERT_TRUE(render_preview(s, nullptr, look_down(PreviewMode::Albedo), Context{}, img));
  for (size_t i = 0; i < img.rgb.size(); ++i) ASSERT_FLOAT_EQ(img.rgb[i], 0.37f) << i;
}

// White furnace: inside a closed emissive box with albedo 0, every pixel is exactly the
// emitted radiance in every shaded mode (lit reads a bake, reference the path tracer).
TEST(Preview, FurnaceRendersTheExactConstant) {
  Scene s;
  const int m = test::add_material(s, 0.f, 3.5f);
  test::add_box(s, {-2, -2, -2}, {2, 2, 2}, true, m);
  DdgiSettings ds;
  ds.grid.counts = {2, 2, 2};
  ds.rays = 64;
  loader::BakeFile bake;
  ASSERT_TRUE(bake_to_file(s, ds, bake).is_ok());
  PreviewSettings ps = look_down(PreviewMode::Lit);
  ps.eye = {0.f, 1.f, 0.5f};
  for (PreviewMode mode : {PreviewMode::Lit, PreviewMode::Reference}) {
    ps.mode = mode;
    ps.spp = 4;
    PreviewImage img;
    ASSERT_TRUE(render_preview(s, &bake, ps, Context{}, img).is_ok());
    for (size_t i = 0; i < img.rgb.size(); ++i) ASSERT_FLOAT_EQ(img.rgb[i], 3.5f) << preview_mode_name(mode) << " " << i;
  }
}

// rho E / pi in nits: direct sunlight (exact) plus the bake's indirect, which is ~0 here (the
// plane's upper hemisphere is black sky).
TEST(Preview, SunlitPlaneRendersRhoEOverPi) {
  const float rho = 0.5f, E = 1000.f;
  const Scene s = sunlit_plane(rho);
  DdgiSettings ds = test::probe_grid({-2.f, 0.5f, -2.f}, {2.f, 1.5f, 2.f}, {3, 2, 3}, 128);
  SunLight sun;
  sun.direction = {0.f, -1.f, 0.f};
  sun.lux = E;
  ds.suns.push_back(sun);
  loader::BakeFile bake;
  ASSERT_TRUE(bake_to_file(s, ds, bake).is_ok());
  PreviewImage img;
  ASSERT_TRUE(render_preview(s, &bake, look_down(PreviewMode::Lit), Context{}, img).is_ok());
  ASSERT_TRUE(all_finite(img));
  const float expected = rho * E / kernels::kPi;
  for (int y = 8; y < 24; ++y)
    for (int x = 8; x < 24; ++x) EXPECT_NEAR(lum(img, x, y), expected, 0.01f * expected) << x << "," << y;
  std::printf("sunlit plane: lit %.3f nits at the centre, rho E / pi = %.3f\n", double(lum(img, 16, 16)),
              double(expected));
  // Without the bake's recorded sun the plane is dark: the preview's light comes from the bake.
  PreviewSettings ps = look_down(PreviewMode::Lit);
  ps.lights_from_bake = false;
  ASSERT_TRUE(render_preview(s, &bake, ps, Context{}, img).is_ok());
  EXPECT_LT(lum(img, 16, 16), 0.01f * expected);
}

TEST(Preview, ProbesInsideAClosedBoxAreDrawnInactive) {
  Scene s;
  const int floor_m = test::add_material(s, 0.5f), box_m = test::add_material(s, 0.5f);
  test::add_quad(s, {-10, -1, -10}, {10, -1, -10}, {10, -1, 10}, {-10, -1, 10}, {0, 1, 0}, floor_m);
  test::add_box(s, {-1, -1, -1}, {1, 1, 1}, false, box_m);  // closed solid
  DdgiSettings ds = test::probe_grid({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, {2, 2, 2}, 64);
  SunLight sun;
  sun.direction = {0.3f, -1.f, 0.2f};
  sun.lux = 1000.f;
  ds.suns.push_back(sun);
  loader::BakeFile bake;
  ASSERT_TRUE(bake_to_file(s, ds, bake).is_ok());
  const auto& vol = bake.ddgi_volumes()[0];
  PreviewSettings ps;
  ps.mode = PreviewMode::Probes;
  ps.width = 160;
  ps.height = 120;
  ps.camera_given = true;
  ps.eye = {3.f, 2.5f, 4.f};
  ps.target = {0.f, 0.f, 0.f};
  PreviewImage img;
  PreviewStats stats;
  ASSERT_TRUE(render_preview(s, &bake, ps, Context{}, img, &stats).is_ok());
  const std::vector<uint8_t> rgb = tonemap_rgb8(img, Tonemap{});
  PreviewCamera cam;
  std::string desc;
  ASSERT_TRUE(resolve_camera(s, ps, cam, desc).is_ok());
  int checked = 0;
  for (uint32_t p = 0; p < vol.probe_count(); ++p) {
    ASSERT_EQ(vol.state(p), uint32_t(GIBAKE_PROBE_INACTIVE)) << "probe " << p << " inside the solid";
    const auto pos = vol.probe_position(p);
    float px, py;
    ASSERT_TRUE(cam.project({pos[0], pos[1], pos[2]}, ps.width, ps.height, px, py));
    const size_t i = (size_t(py) * size_t(ps.width) + size_t(px)) * 3;
    EXPECT_EQ(rgb[i], 255) << p;
    EXPECT_EQ(rgb[i + 1], 0) << p;
    EXPECT_EQ(rgb[i + 2], 255) << p;
    ++checked;
  }
  EXPECT_EQ(checked, 8);
  EXPECT_EQ(stats.inactive_drawn, 8);
}

class CornellPreview : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(import_scene(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf", ImportOptions{},
                             Context{}, scene)
                    .is_ok());
  }
  // The sample baked with `rays` a probe (and counts^3 probes when counts > 0) into `bake`.
  Status bake(uint32_t rays, loader::BakeFile& bake, int counts = 0) const {
    DdgiSettings ds;
    if (counts > 0) ds.grid.counts = {counts, counts, counts};
    ds.rays = rays;
    return bake_to_file(scene, ds, bake);
  }
  Scene scene;
};

TEST_F(CornellPreview, LitIsFiniteAndBrighterNearTheLightThanInShadow) {
  ASSERT_FALSE(scene.cameras.empty()) << "the sample's camera is imported";
  ASSERT_FALSE(scene.lights.empty());
  loader::BakeFile bake;
  ASSERT_TRUE(this->bake(128, bake).is_ok());
  PreviewSettings ps;
  ps.width = ps.height = 128;
  PreviewImage img;
  ASSERT_TRUE(render_preview(scene, &bake, ps, Context{}, img).is_ok());
  ASSERT_TRUE(all_finite(img));
  // Near the light: the ceiling-adjacent band of the back wall just below the lamp; in shadow:
  // the floor strip behind/under the boxes (bottom rows); compare band means.
  PreviewCamera cam;
  std::string d;
  ASSERT_TRUE(resolve_camera(scene, ps, cam, d).is_ok());
  const auto& L = scene.lights[0].position;
  float lx, ly;
  ASSERT_TRUE(cam.project({L[0], L[1], L[2]}, ps.width, ps.height, lx, ly));
  double near_sum = 0, far_sum = 0;
  int near_n = 0, far_n = 0;
  for (int y = 0; y < ps.height; ++y)
    for (int x = 0; x < ps.width; ++x) {
      const float dist = std::hypot(float(x) - lx, float(y) - ly);
      if (dist > 6.f && dist < 20.f) near_sum += lum(img, x, y), ++near_n;
      if (y > ps.height * 3 / 4 && std::fabs(float(x) - lx) < 10.f) far_sum += lum(img, x, y), ++far_n;
    }
  std::printf("cornell lit: mean %.3f nits near the light, %.3f under the boxes\n", near_sum / near_n,
              far_sum / far_n);
  EXPECT_GT(near_sum / near_n, 1.5 * far_sum / far_n);
}

// The reference's noise estimated from its own two halves predicts how often it lies within 5% (the
// middle of its spread, where the share is most sensitive) of a far better converged reference of
// the same view (independent samples: another seed, 64x the samples): the share of blocks and the
// median block error agree within the block count's sampling error.
TEST_F(CornellPreview, ReferenceNoiseFromItsHalvesPredictsItsErrorAgainstAConvergedOne) {
  PreviewSettings ps;
  ps.mode = PreviewMode::Reference;
  ps.width = 128;
  ps.height = 96;  // 192 blocks of 8x8
  ps.spp = 2;
  PreviewImage noisy, converged;
  ASSERT_TRUE(render_preview(scene, nullptr, ps, Context{}, noisy).is_ok());
  ps.spp = 128;
  ps.seed = 7;
  ASSERT_TRUE(render_preview(scene, nullptr, ps, Context{}, converged).is_ok());
  ReferenceNoise estimate;
  ASSERT_TRUE(reference_noise(noisy, 8, 0.05f, 0.001f, estimate).is_ok());
  BlockComparison measured;
  ASSERT_TRUE(compare_blocks(noisy, converged, 8, 0.05f, 0.001f, measured).is_ok());
  ASSERT_EQ(estimate.blocks, measured.blocks);
  ASSERT_GT(estimate.blocks, 150u);
  // Median |ratio - 1| over the blocks: the measured counterpart of the estimate's median error.
  std::vector<double> errors;
  const int bx = 16, by = 12;
  std::vector<double> a(size_t(bx) * by), b(a.size());
  for (int y = 0; y < by * 8; ++y)
    for (int x = 0; x < bx * 8; ++x) {
      a[size_t(y / 8) * bx + x / 8] += lum(noisy, x, y);
      b[size_t(y / 8) * bx + x / 8] += lum(converged, x, y);
    }
  for (size_t i = 0; i < a.size(); ++i)
    if (b[i] > 0.0) errors.push_back(std::abs(a[i] / b[i] - 1.0));
  std::sort(errors.begin(), errors.end());
  const double measured_median = errors[errors.size() / 2];
  std::printf("2 spp: estimated within 5%% %.2f, median error %.3f; against 128 spp: within %.2f, median %.3f\n",
              estimate.within, estimate.median_error, measured.ratio.within, measured_median);
  // The share is a binomial count over ~190 blocks (sd <= 0.036) on each side.
  EXPECT_NEAR(estimate.within, measured.ratio.within, 0.12);
  EXPECT_NEAR(estimate.median_error / measured_median, 1.0, 0.3);
  // Noisy enough that the estimate is informative, neither 0 nor 1.
  EXPECT_GT(measured.ratio.within, 0.15);
  EXPECT_LT(measured.ratio.within, 0.85);
  ps.spp = 1;
  PreviewImage single;
  ASSERT_TRUE(render_preview(scene, nullptr, ps, Context{}, single).is_ok());
  EXPECT_FALSE(reference_noise(single, 8, 0.10f, 0.001f, estimate).is_ok()) << "one sample has no halves";
}

TEST_F(CornellPreview, ImagesDoNotDependOnTheThreadCount) {
  loader::BakeFile bake;
  ASSERT_TRUE(this->bake(64, bake).is_ok());
  for (PreviewMode mode : {PreviewMode::Lit, PreviewMode::Reference}) {
    PreviewSettings ps;
    ps.mode = mode;
    ps.width = ps.height = 48;
    ps.spp = 4;
    PreviewImage a, b;
    Context one, two;
    one.threads = 1;
    two.threads = 2;
    ASSERT_TRUE(render_preview(scene, &bake, ps, one, a).is_ok());
    ASSERT_TRUE(render_preview(scene, &bake, ps, two, b).is_ok());
    EXPECT_EQ(a.rgb, b.rgb) << preview_mode_name(mode);
  }
}

TEST_F(CornellPreview, ReferenceDifferenceFallsWithMoreProbesAndSamples) {
  double rms[2][2];
  const int counts[2] = {3, 8}, spps[2] = {4, 64};
  for (int g = 0; g < 2; ++g) {
    loader::BakeFile bake;
    ASSERT_TRUE(this->bake(256, bake, counts[g]).is_ok());
    PreviewSettings ps;
    ps.width = ps.height = 64;
    PreviewImage lit;
    ASSERT_TRUE(render_preview(scene, &bake, ps, Context{}, lit).is_ok());
    for (int k = 0; k < 2; ++k) {
      ps.mode = PreviewMode::Reference;
      ps.spp = spps[k];
      PreviewImage ref;
      ASSERT_TRUE(render_preview(scene, &bake, ps, Context{}, ref).is_ok());
      ASSERT_TRUE(all_finite(ref));
      PreviewDiff diff;
      ASSERT_TRUE(diff_previews(lit, ref, 0.01f, diff).is_ok());
      rms[g][k] = diff.rms;
      std::printf("cornell %d^3 probes, reference %d spp: relative RMS %.4f (%zu pixels)\n", counts[g], spps[k],
                  diff.rms, diff.pixels);
      ps.mode = PreviewMode::Lit;
    }
  }
  EXPECT_LT(rms[1][1], rms[0][1]) << "more probes";
  EXPECT_LT(rms[1][1], rms[1][0]) << "more samples";
}

}  // namespace
}  // namespace gibake

namespace gibake {
namespace {

int run(const std::string& args) { return test::run_gibake_cli(args).exit_code; }

TEST(PreviewCli, WritesPngAndExrAndReportsDocumentedExitCodes) {
  char tmpl[] = "/tmp/gibake_preview_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl, scene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  ASSERT_EQ(run("bake " + scene + " --ddgi --rays 64 --progress lines --out " + dir + "/c.gibake"), 0);
  const std::string common = "preview " + scene + " --bake " + dir + "/c.gibake --size 48x32 --progress lines ";
  for (const char* mode : {"lit", "indirect", "probes", "albedo", "normals"})
    EXPECT_EQ(run(common + "--mode " + mode + " --out " + dir + "/" + mode + ".png"), 0) << mode;
  EXPECT_EQ(run(common + "--out " + dir + "/lit.exr"), 0);
  EXPECT_EQ(run(common + "--reference --spp 2 --diff " + dir + "/diff.png --out " + dir + "/ref.png"), 0);
  for (const char* f : {"lit.png", "probes.png", "lit.exr", "ref.png", "diff.png"}) {
    FILE* fp = std::fopen((dir + "/" + f).c_str(), "rb");
    ASSERT_NE(fp, nullptr) << f;
    unsigned char magic[4] = {0, 0, 0, 0};
    EXPECT_EQ(std::fread(magic, 1, 4, fp), 4u);
    std::fclose(fp);
    if (std::string(f).find(".exr") != std::string::npos) EXPECT_EQ(magic[0], 0x76) << f;  // EXR magic 76 2f 31 01
    else EXPECT_EQ(magic[1], 'P') << f;
  }
  EXPECT_EQ(run("preview " + scene + " --out " + dir + "/x.png"), 1) << "lit without --bake";
  EXPECT_EQ(run(common + "--out " + dir + "/x.jpg"), 1) << "unknown extension";
  EXPECT_EQ(run(common + "--mode bogus --out " + dir + "/x.png"), 1);
  EXPECT_EQ(run("preview " + scene + " --bake " + dir + "/missing.gibake --out " + dir + "/x.png"), 2);
  EXPECT_EQ(run(common + "--mode albedo --out " + dir + "/c.gibake.png"), 0);
  EXPECT_NE(run(common + "--mode albedo --out " + scene), 0) << "a scene path as the output is refused";
  std::system(("rm -rf " + dir).c_str());
}

// A reference saved once (`--reference --out F.exr`) and compared with later (`--reference-image`)
// gives the very figures of one rendered alongside, its noise line included; files that are not
// such a reference are refused before anything is written.
TEST(PreviewCli, ComparesWithASavedReferenceImage) {
  char tmpl[] = "/tmp/gibake_preview_ref_XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl, scene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  ASSERT_EQ(run("bake " + scene + " --ddgi --rays 64 --out " + dir + "/c.gibake"), 0);
  const std::string bake = "preview " + scene + " --bake " + dir + "/c.gibake ", common = bake + "--size 48x32 ";
  ASSERT_EQ(run("preview " + scene + " --reference --size 48x32 --spp 16 --out " + dir + "/ref.exr"), 0);
  const test::CliResult rendered =
      test::run_gibake_cli(common + "--spp 16 --diff " + dir + "/d1.png --out " + dir + "/l1.png");
  const test::CliResult saved = test::run_gibake_cli(common + "--reference-image " + dir + "/ref.exr --diff " + dir +
                                                     "/d2.png --block-map " + dir + "/m2.png --out " + dir + "/l2.png");
  ASSERT_EQ(rendered.exit_code, 0) << rendered.err;
  ASSERT_EQ(saved.exit_code, 0) << saved.err;
  auto line = [](const std::string& text, const std::string& head) {
    const size_t at = text.find(head);
    return at == std::string::npos ? std::string() : text.substr(at, text.find('\n', at) - at);
  };
  for (const char* head : {"8x8 blocks:", "reference noise", "relative RMS"}) {
    EXPECT_FALSE(line(rendered.out, head).empty()) << head;
    EXPECT_EQ(line(saved.out, head), line(rendered.out, head)) << head;
  }
  // The blocks farthest off, listed as --explain's X,Y (block centres inside the 48x32 view) when
  // any block is off, and their map (a PNG of the view's size).
  const std::string worst = line(saved.out, "worst 8x8 blocks");
  EXPECT_EQ(worst, line(rendered.out, "worst 8x8 blocks"));
  std::smatch within;
  const std::string blocks_line = line(saved.out, "8x8 blocks:");
  ASSERT_TRUE(std::regex_search(blocks_line, within, std::regex(R"(8x8 blocks: ([0-9.]+)%)"))) << blocks_line;
  if (std::stod(within[1]) < 100.0) {
    std::smatch first;
    ASSERT_TRUE(std::regex_search(worst, first, std::regex(R"(centre\): ([0-9]+),([0-9]+) ([0-9.]+|nan))")))
        << saved.out;
    EXPECT_EQ(std::stoi(first[1]) % 8, 4);
    EXPECT_EQ(std::stoi(first[2]) % 8, 4);
    EXPECT_LT(std::stoi(first[1]), 48);
    EXPECT_LT(std::stoi(first[2]), 32);
  }
  if (FILE* fp = std::fopen((dir + "/m2.png").c_str(), "rb")) {
    unsigned char header[24] = {};
    EXPECT_EQ(std::fread(header, 1, 24, fp), 24u);
    std::fclose(fp);
    EXPECT_EQ(header[1], 'P');
    EXPECT_EQ((header[16] << 24 | header[17] << 16 | header[18] << 8 | header[19]), 48) << "width";
    EXPECT_EQ((header[20] << 24 | header[21] << 16 | header[22] << 8 | header[23]), 32) << "height";
  } else {
    ADD_FAILURE() << "--block-map wrote nothing";
  }
  EXPECT_EQ(run(common + "--block-map " + dir + "/m3.png --out " + dir + "/l3.png"), 1) << "--block-map without --diff";
  EXPECT_EQ(run(common + "--reference-image " + dir + "/ref.exr --diff " + dir + "/d3.png --block-map " + dir +
                "/m3.jpg --out " + dir + "/l3.png"),
            1)
      << "--block-map not a PNG";
  const test::CliResult same = test::run_gibake_cli(common + "--reference-image " + dir + "/ref.exr --diff " + dir +
                                                    "/d3.png --block-map " + dir + "/d3.png --out " + dir + "/l3.png");
  EXPECT_EQ(same.exit_code, 1) << "--block-map naming --diff's file";
  EXPECT_NE(same.err.find("names the same file as --diff"), std::string::npos) << same.err;
  EXPECT_NE(access((dir + "/m3.png").c_str(), F_OK), 0) << "m3.png written";
  // Another renderer's EXR (here a lit view: R, G, B and nothing else) serves; its noise is unknown.
  ASSERT_EQ(run(common + "--out " + dir + "/other.exr"), 0);
  const test::CliResult other = test::run_gibake_cli(common + "--reference-image " + dir + "/other.exr --diff " + dir +
                                                     "/d4.png --out " + dir + "/l4.png");
  ASSERT_EQ(other.exit_code, 0) << other.err;
  EXPECT_FALSE(line(other.out, "8x8 blocks:").empty());
  EXPECT_TRUE(line(other.out, "reference noise").empty()) << other.out;
  EXPECT_NE(line(other.out, "relative RMS").find("the given reference"), std::string::npos) << other.out;
  EXPECT_EQ(run(bake + "--reference-image " + dir + "/ref.exr --size 48x30 --diff " + dir + "/d3.png --out " + dir +
                "/l3.png"),
            3)
      << "another size";
  EXPECT_EQ(run(common + "--reference-image " + dir + "/c.gibake --diff " + dir + "/d3.png --out " + dir + "/l3.png"),
            3)
      << "not an EXR";
  EXPECT_EQ(run(common + "--reference-image " + dir + "/none.exr --diff " + dir + "/d3.png --out " + dir + "/l3.png"),
            2)
      << "missing";
  EXPECT_EQ(run(common + "--reference-image " + dir + "/ref.exr --out " + dir + "/l3.png"), 1) << "without --diff";
  EXPECT_EQ(run(common + "--reference-image " + dir + "/ref.exr --diff " + dir + "/d3.png --out " + dir + "/ref.exr"),
            1)
      << "over the reference it reads";
  for (const char* f : {"d3.png", "l3.png"}) EXPECT_NE(access((dir + "/" + f).c_str(), F_OK), 0) << f << " written";
  // A reference with no lit pixel compares nothing (figures of 0 would read as a match): refused,
  // exit 3, before any image is written.
  PreviewImage black;
  black.width = 48;
  black.height = 32;
  black.rgb.assign(size_t(48 * 32 * 3), 0.f);
  ASSERT_TRUE(write_preview(dir + "/black.exr", black, Tonemap{}).is_ok());
  const test::CliResult dark = test::run_gibake_cli(common + "--reference-image " + dir + "/black.exr --diff " + dir +
                                                    "/d5.png --out " + dir + "/l5.png");
  EXPECT_EQ(dark.exit_code, 3) << dark.err;
  EXPECT_NE(dark.err.find("black.exr: reference: no pixel brighter than 0 cd/m^2: nothing to compare"),
            std::string::npos)
      << dark.err;
  for (const char* f : {"d5.png", "l5.png"}) EXPECT_NE(access((dir + "/" + f).c_str(), F_OK), 0) << f << " written";
  std::system(("rm -rf " + dir).c_str());
}

}  // namespace
}  // namespace gibake
