// gibake's path-traced gather against an independent renderer: Blender Cycles panoramas at the
// probe positions, projected to SH L2 in gibake's basis by scripts/cycles_reference.py and
// committed as tests/reference/*.cycles.json (CI never runs Blender).
//
// The figure: relative RMS of irradiance, pooled over every active probe, 64 directions and the
// three channels: sqrt(sum (E_gibake - E_cycles)^2 / sum E_cycles^2). Tolerance 2% in path mode.
// The probe-feedback mode's figure is printed beside it (it is biased; docs/BENCHMARKS.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "tests/loader/test_util.h"

namespace gibake {
namespace {

using Sh = std::array<float, 27>;  // [coefficient][channel], cd/m^2, as the bake file stores it

struct ReferenceProbe {
  bool inside_solid = false;  // analytic, from the scene's construction (make_scenes.py)
  bool black = false;         // Cycles saw (almost) no light: < 1e-5 of the median probe
  Sh sh{};
};

struct Reference {
  std::string scene;
  std::vector<std::string> grid_args;
  std::vector<ReferenceProbe> probes;
};

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return nlohmann::json::parse(in);
}

std::string reference_dir() { return std::string(GIBAKE_SOURCE_DIR) + "/tests/reference/"; }

Reference load_reference(const std::string& name, const std::string& cycles_file) {
  Reference ref;
  ref.scene = reference_dir() + name + ".gltf";
  const nlohmann::json grid = read_json(reference_dir() + name + ".probes.json");
  const nlohmann::json cycles = read_json(reference_dir() + cycles_file);
  for (const auto& a : grid["gibake_grid_args"]) ref.grid_args.push_back(a.get<std::string>());
  EXPECT_EQ(grid["probes"].size(), cycles["probes"].size());
  std::vector<float> levels;
  for (size_t i = 0; i < cycles["probes"].size(); ++i) {
    ReferenceProbe p;
    p.inside_solid = grid["probes"][i]["inside_solid"].get<bool>();
    const auto& sh = cycles["probes"][i]["sh"];
    for (int c = 0; c < 9; ++c)
      for (int k = 0; k < 3; ++k) p.sh[size_t(c * 3 + k)] = sh[c][k].get<float>();
    levels.push_back(p.sh[0] + p.sh[1] + p.sh[2]);
    ref.probes.push_back(p);
  }
  std::vector<float> sorted = levels;
  std::sort(sorted.begin(), sorted.end());
  const float median = sorted[sorted.size() / 2];
  for (size_t i = 0; i < ref.probes.size(); ++i) ref.probes[i].black = levels[i] < 1e-5f * median;
  return ref;
}

std::vector<loader::Vec3> sphere_directions(int n) {  // Fibonacci sphere
  std::vector<loader::Vec3> d;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - y * y), phi = golden * i;
    d.push_back({float(r * std::cos(phi)), float(y), float(r * std::sin(phi))});
  }
  return d;
}

// Pooled relative RMS of irradiance over the probes `use` selects.
template <class A, class B>
double relative_rms(size_t probes, const A& sh_a, const B& sh_b, const std::vector<bool>& use) {
  double num = 0.0, den = 0.0;
  for (size_t p = 0; p < probes; ++p) {
    if (!use[p]) continue;
    const Sh a = sh_a(p), b = sh_b(p);
    for (const loader::Vec3& n : sphere_directions(64)) {
      const loader::Rgb ea = loader::sh_irradiance(a.data(), 9, n), eb = loader::sh_irradiance(b.data(), 9, n);
      for (int c = 0; c < 3; ++c) {
        num += double(ea[c] - eb[c]) * double(ea[c] - eb[c]);
        den += double(eb[c]) * double(eb[c]);
      }
    }
  }
  return std::sqrt(num / den);
}

Sh file_sh(const loader::DdgiVolume& v, uint32_t probe) {
  Sh s{};
  for (uint32_t c = 0; c < 9; ++c)
    for (uint32_t k = 0; k < 3; ++k) s[c * 3 + k] = v.sh(probe, c, k);
  return s;
}

struct Bake {
  loader::BakeFile file;
  double rel_rms = 0.0;
};

// Bakes the reference's grid with `options` and compares it with the reference.
void bake_and_compare(const Reference& ref, const std::string& options, Bake& out) {
  const std::string dir = test::scratch_dir("reference");
  const std::string path = dir + "/probes.gibake";
  std::string args = ref.scene + " --ddgi --out " + path + " " + options;
  for (const std::string& a : ref.grid_args) args += " " + a;
  const test::RunResult run = test::run_gibake(args);
  ASSERT_EQ(run.exit_code, 0) << run.out;
  ASSERT_FALSE(out.file.open(path));
  ASSERT_EQ(out.file.ddgi_volumes().size(), 1u);
  const loader::DdgiVolume& v = out.file.ddgi_volumes()[0];
  ASSERT_EQ(v.probe_count(), ref.probes.size());
  std::vector<bool> use(ref.probes.size());
  for (size_t p = 0; p < use.size(); ++p) use[p] = !ref.probes[p].black && v.state(uint32_t(p)) != GIBAKE_PROBE_INACTIVE;
  out.rel_rms = relative_rms(
      ref.probes.size(), [&](size_t p) { return file_sh(v, uint32_t(p)); }, [&](size_t p) { return ref.probes[p].sh; },
      use);
  std::filesystem::remove_all(dir);
}

// Probes inside closed solids and probes Cycles sees as black are inactive; every probe Cycles
// sees light at is active.
void expect_states_match(const Reference& ref, const loader::DdgiVolume& v) {
  for (size_t p = 0; p < ref.probes.size(); ++p) {
    const bool inactive = v.state(uint32_t(p)) == GIBAKE_PROBE_INACTIVE;
    if (ref.probes[p].inside_solid) {
      EXPECT_TRUE(ref.probes[p].black) << "probe " << p << ": Cycles sees light inside";
    }
    if (ref.probes[p].black) {
      EXPECT_TRUE(inactive) << "probe " << p << " is black in Cycles but active";
    } else {
      EXPECT_FALSE(inactive) << "probe " << p << " sees light in Cycles but is inactive";
    }
  }
}

constexpr double kTolerance = 0.02;
const char* kPathOptions = "--gather path --rays 16384 --bounces 16 --seed 7";
const char* kProbeOptions = "--gather probes --rays 4096 --bounces 16 --seed 7";

void check_scene(const std::string& name) {
  const Reference ref = load_reference(name, name + ".cycles.json");
  Bake path, probes;
  bake_and_compare(ref, kPathOptions, path);
  bake_and_compare(ref, kProbeOptions, probes);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  std::printf("%s: relative RMS of irradiance against Cycles: path %.4f, probes %.4f\n", name.c_str(), path.rel_rms,
              probes.rel_rms);
  ::testing::Test::RecordProperty("path_relative_rms", std::to_string(path.rel_rms));
  ::testing::Test::RecordProperty("probes_relative_rms", std::to_string(probes.rel_rms));
  EXPECT_LE(path.rel_rms, kTolerance);
  expect_states_match(ref, path.file.ddgi_volumes()[0]);
  expect_states_match(ref, probes.file.ddgi_volumes()[0]);
}

TEST(CyclesReference, CornellBlocksPathGatherWithinTwoPercent) { check_scene("cornell_blocks"); }

TEST(CyclesReference, TwoRoomsPathGatherWithinTwoPercent) { check_scene("two_rooms"); }

// The reference's own noise: two Cycles seeds must differ by far less than the tolerance, so the
// test above measures gibake, not Cycles.
TEST(CyclesReference, TwoSeedsOfTheReferenceAgree) {
  const Reference a = load_reference("two_rooms", "two_rooms.cycles.json");
  const Reference b = load_reference("two_rooms", "two_rooms.cycles_seed1.json");
  std::vector<bool> use(a.probes.size());
  for (size_t p = 0; p < use.size(); ++p) use[p] = !a.probes[p].black;
  const double rms = relative_rms(
      a.probes.size(), [&](size_t p) { return b.probes[p].sh; }, [&](size_t p) { return a.probes[p].sh; }, use);
  std::printf("two_rooms: relative RMS between Cycles seeds 0 and 1: %.5f\n", rms);
  EXPECT_LE(rms, kTolerance / 4);
}

}  // namespace
}  // namespace gibake
