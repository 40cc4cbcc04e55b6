// gibake's reference path tracer (`preview --reference`), the yardstick of every picture figure,
// against an independent renderer: Blender Cycles renders of camera views of three scenes
// (tests/reference/views.json, made by make_scenes.py: a Cornell box lit by an emissive patch, a
// room lit by a sun through a window and a ceiling patch, and an open court with a textured floor,
// an alpha-masked lattice, a sun and a sky), rendered by scripts/cycles_reference.py's camera mode
// at up to 1024 bounces, twice with different seeds, and committed as 8x8-pixel block means
// (*.view.cycles.json; CI never runs Blender).
//
// Blocks are compared by luminance, ratio gibake / Cycles, leaving out blocks darker than 0.1% of
// the view's mean (black against black says nothing). What "within its noise" means here: the two
// Cycles renders' own disagreement sets the scale (their blocks' relative differences), and
// gibake's blocks must agree with the Cycles mean as closely as a render of its sample count can:
// every view's mean luminance within 2%, the median block ratio within 2%, and at least 97% of the
// blocks within 10%.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bake/scene/sky.h"
#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace gibake {
namespace {

using namespace gibake::test;  // run_gibake_cli, shell_quote, ScratchDir

constexpr int kBlock = 8;
constexpr int kSpp = 256;  // gibake's samples a pixel: 16,384 paths a block

std::string reference_dir() { return std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/"; }

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return nlohmann::json::parse(in);
}

double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

std::string joined(const nlohmann::json& values) {
  std::string s;
  for (const auto& v : values) s += (s.empty() ? "" : ",") + std::to_string(v.get<double>());
  return s;
}

// Block luminances of an image of width x height linear RGB pixels, rows from the top.
std::vector<double> block_luminance(const std::vector<float>& rgb, int width, int height) {
  std::vector<double> out;
  for (int by = 0; by < height / kBlock; ++by)
    for (int bx = 0; bx < width / kBlock; ++bx) {
      double sum = 0.0;
      for (int y = by * kBlock; y < (by + 1) * kBlock; ++y)
        for (int x = bx * kBlock; x < (bx + 1) * kBlock; ++x) {
          const float* p = &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3];
          sum += luminance(p[0], p[1], p[2]);
        }
      out.push_back(sum / (kBlock * kBlock));
    }
  return out;
}

std::vector<double> cycles_luminance(const nlohmann::json& blocks) {
  std::vector<double> out;
  for (const auto& b : blocks) out.push_back(luminance(b[0].get<double>(), b[1].get<double>(), b[2].get<double>()));
  return out;
}

struct Agreement {
  size_t counted = 0;
  double within = 0.0, median = 0.0, mean_ratio = 0.0;
};

// Blocks of `a` against `b` (luminance ratio a / b) over the blocks of b above the floor.
Agreement compare(const std::vector<double>& a, const std::vector<double>& b) {
  double mean_b = 0.0, sum_a = 0.0, sum_b = 0.0;
  for (double v : b) mean_b += v / double(b.size());
  std::vector<double> ratios;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (b[i] <= 1e-3 * mean_b) continue;
    ratios.push_back(a[i] / b[i]);
    sum_a += a[i];
    sum_b += b[i];
  }
  Agreement g;
  g.counted = ratios.size();
  if (ratios.empty()) return g;
  g.within = double(std::count_if(ratios.begin(), ratios.end(), [](double r) { return std::fabs(r - 1.0) <= 0.1; })) /
             double(ratios.size());
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  g.median = ratios[ratios.size() / 2];
  g.mean_ratio = sum_a / sum_b;
  return g;
}

class PictureReference : public ::testing::TestWithParam<std::string> {
 protected:
  ScratchDir scratch_{"picture_reference"};
};

TEST_P(PictureReference, ReferenceMatchesCyclesWithinItsNoise) {
  const std::string name = GetParam();
  const nlohmann::json views = read_json(reference_dir() + "views.json");
  nlohmann::json view;
  for (const auto& v : views["views"])
    if (v["name"] == name) view = v;
  ASSERT_FALSE(view.is_null()) << name;
  const nlohmann::json cycles = read_json(reference_dir() + name + ".view.cycles.json");
  const int width = view["width"].get<int>(), height = view["height"].get<int>();
  ASSERT_EQ(cycles["blocks_x"].get<int>(), width / kBlock);
  ASSERT_EQ(cycles["blocks_y"].get<int>(), height / kBlock);

  const std::string out = scratch_.path("ref.exr");
  const CliResult r = run_gibake_cli(
      "preview " + shell_quote(reference_dir() + view["scene"].get<std::string>()) + " --reference --camera " +
      joined(view["eye"]) + "," + joined(view["target"]) + ",0,1,0 --fov " + std::to_string(view["fov"].get<double>()) +
      " --size " + std::to_string(width) + "x" + std::to_string(height) + " --sky " + joined(view["sky"]) +
      " --spp " + std::to_string(kSpp) + " --out " + shell_quote(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Sky image;
  const Status read = load_sky_exr(out, image);
  ASSERT_TRUE(read) << read.message();
  ASSERT_EQ(image.width, width);
  ASSERT_EQ(image.height, height);

  const std::vector<double> seed_a = cycles_luminance(cycles["renders"][0]);
  const std::vector<double> seed_b = cycles_luminance(cycles["renders"][1]);
  std::vector<double> truth(seed_a.size());
  for (size_t i = 0; i < truth.size(); ++i) truth[i] = 0.5 * (seed_a[i] + seed_b[i]);
  const Agreement ours = compare(block_luminance(image.rgb, width, height), truth);
  const Agreement theirs = compare(seed_a, seed_b);
  std::printf("%s: %zu blocks; gibake %d spp vs Cycles: %.1f%% within 10%%, median %.3f, mean %.3f; "
              "Cycles seed against seed (%d spp each): %.1f%% within 10%%, median %.3f\n",
              name.c_str(), ours.counted, kSpp, 100 * ours.within, ours.median, ours.mean_ratio,
              cycles["samples"].get<int>(), 100 * theirs.within, theirs.median);
  ASSERT_GE(ours.counted, size_t(width / kBlock * height / kBlock / 2));
  EXPECT_NEAR(ours.mean_ratio, 1.0, 0.02);
  EXPECT_NEAR(ours.median, 1.0, 0.02);
  EXPECT_GE(ours.within, 0.97);
}

INSTANTIATE_TEST_SUITE_P(Views, PictureReference, ::testing::Values("cornell_blocks", "two_rooms", "lattice_court"),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

}  // namespace
}  // namespace gibake
