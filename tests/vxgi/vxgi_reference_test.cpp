// Voxel GI against the committed Cycles references (tests/reference/), read the way an engine reads
// it (the loader's calibrated diffuse cone trace), with the same pooled figure as the DDGI reference
// test: relative RMS of irradiance over the probes Cycles sees light at, 64 normals, 3 channels.
// The bounds are regression guards around the figures measured at these settings (docs/BENCHMARKS.md,
// "Voxel GI"): they are far from the DDGI bake's 2%, which is the point of printing them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/loader/test_util.h"

namespace gibake {
namespace {

struct Figures {
  double rel_rms = 0.0, mean_ratio = 0.0, dark_fraction = 0.0;
};

double sh_irradiance(const nlohmann::json& sh, const loader::Vec3& n, int c) {
  const float x = n[0], y = n[1], z = n[2];
  const double basis[9] = {0.282095, 0.488603 * y, 0.488603 * z, 0.488603 * x, 1.092548 * x * y,
                           1.092548 * y * z, 0.315392 * (3 * z * z - 1), 1.092548 * x * z, 0.546274 * (x * x - y * y)};
  const double a[9] = {M_PI, 2 * M_PI / 3, 2 * M_PI / 3, 2 * M_PI / 3, M_PI / 4, M_PI / 4, M_PI / 4, M_PI / 4, M_PI / 4};
  double e = 0.0;
  for (int k = 0; k < 9; ++k) e += a[k] * basis[k] * sh[k][c].get<double>();
  return std::max(0.0, e);
}

// Measurements beyond the guards (docs/BENCHMARKS.md's tables): GIBAKE_VXGI_REF_OPTIONS replaces
// the bake options, GIBAKE_VXGI_REF_CONES picks the diffuse set (6, precomputed: the 16 precomputed
// cones, or N > 6 spiral cones), GIBAKE_VXGI_REF_LIMIT / GIBAKE_VXGI_REF_STEP the cone options'
// self_occlusion_limit / step_scale.
loader::ConeOptions reference_cones() {
  loader::ConeOptions o;
  const char* c = std::getenv("GIBAKE_VXGI_REF_CONES");
  if (c && std::string(c) == "precomputed") o.precomputed_cones = true;
  else if (c) o.diffuse_cones = uint32_t(std::atoi(c));
  if (const char* l = std::getenv("GIBAKE_VXGI_REF_LIMIT")) o.self_occlusion_limit = float(std::atof(l));
  if (const char* st = std::getenv("GIBAKE_VXGI_REF_STEP")) o.step_scale = float(std::atof(st));
  return o;
}

Figures compare(const std::string& name, std::string options) {
  if (const char* env = std::getenv("GIBAKE_VXGI_REF_OPTIONS")) options = env;
  const loader::ConeOptions cones = reference_cones();
  const std::string dir = test::scratch_dir("vxgi_reference");
  const std::string ref_dir = std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/";
  const std::string out = dir + "/v.gibake";
  const test::RunResult run = test::run_gibake(ref_dir + name + ".gltf --vxgi " + options + " --out " + out);
  EXPECT_EQ(run.exit_code, 0) << run.out;
  loader::BakeFile file;
  EXPECT_FALSE(file.open(out));
  std::ifstream cin(ref_dir + name + ".cycles.json"), gin(ref_dir + name + ".probes.json");
  const nlohmann::json cycles = nlohmann::json::parse(cin), grid = nlohmann::json::parse(gin);
  std::vector<double> level;
  for (const auto& p : cycles["probes"]) level.push_back(p["sh"][0][0].get<double>() + p["sh"][0][1].get<double>() + p["sh"][0][2].get<double>());
  std::vector<double> sorted = level;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  double num = 0, den = 0, sum = 0, sum_ref = 0, dark = 0;
  size_t lit_values = 0, dark_values = 0;
  for (size_t i = 0; i < level.size(); ++i) {
    const auto& probe = cycles["probes"][i];
    const loader::Vec3 p{probe["position"][0].get<float>(), probe["position"][1].get<float>(), probe["position"][2].get<float>()};
    const bool black = level[i] < 1e-5 * median;
    if (black && grid["probes"][i]["inside_solid"].get<bool>()) continue;
    for (int k = 0; k < 64; ++k) {
      const double yy = 1.0 - 2.0 * (k + 0.5) / 64, r = std::sqrt(1 - yy * yy), phi = M_PI * (3 - std::sqrt(5.0)) * k;
      const loader::Vec3 n{float(r * std::cos(phi)), float(yy), float(r * std::sin(phi))};
      loader::Rgb e;
      EXPECT_TRUE(file.sample_vxgi(p, n, e, cones));
      for (int c = 0; c < 3; ++c) {
        if (black) {
          dark += e[size_t(c)];
          ++dark_values;
          continue;
        }
        const double ref = sh_irradiance(probe["sh"], n, c);
        num += (e[size_t(c)] - ref) * (e[size_t(c)] - ref);
        den += ref * ref;
        sum += e[size_t(c)];
        sum_ref += ref;
        ++lit_values;
      }
    }
  }
  std::filesystem::remove_all(dir);
  Figures f;
  f.rel_rms = std::sqrt(num / den);
  f.mean_ratio = sum / sum_ref;
  f.dark_fraction = dark_values ? (dark / double(dark_values)) / (sum / double(lit_values)) : 0.0;
  std::printf("%s %s: VXGI against Cycles: relative RMS %.3f, mean ratio %.3f, dark room %.1f%% of the lit mean "
              "(DDGI path: 0.016, LPV: %s)\n", name.c_str(), options.c_str(), f.rel_rms, f.mean_ratio,
              100.0 * f.dark_fraction, name == "two_rooms" ? "0.852" : "1.037");
  return f;
}

const char* kOptions = "--vxgi-res 32 --vxgi-rays 16 --vxgi-bounces 16";

TEST(VxgiReference, CornellBlocks) {
  const Figures f = compare("cornell_blocks", kOptions);
  EXPECT_LT(f.rel_rms, 0.5);
  EXPECT_GT(f.mean_ratio, 0.8);
  EXPECT_LT(f.mean_ratio, 1.2);
}

TEST(VxgiReference, TwoRooms) {
  const Figures f = compare("two_rooms", kOptions);
  EXPECT_LT(f.rel_rms, 0.5);
  EXPECT_GT(f.mean_ratio, 0.8);
  EXPECT_LT(f.mean_ratio, 1.2);
  EXPECT_LT(f.dark_fraction, 0.5);  // the known thin-wall leak (docs/BENCHMARKS.md); the goal is 2%
}

// --vxgi-sides split at 64 voxels (docs/BENCHMARKS.md, "Voxel GI"). Guards: the leak must stay well
// below the mixed bake's.
TEST(VxgiReference, TwoRoomsSplitSides) {
  const Figures f = compare("two_rooms", "--vxgi-res 64 --vxgi-rays 16 --vxgi-bounces 16 --vxgi-sides split");
  EXPECT_LT(f.rel_rms, 0.3);
  EXPECT_GT(f.mean_ratio, 0.9);
  EXPECT_LT(f.mean_ratio, 1.1);
  EXPECT_LT(f.dark_fraction, 0.18);
}

}  // namespace
}  // namespace gibake
