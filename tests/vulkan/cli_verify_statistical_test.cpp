// `verify --against REF --compare statistical`: two correct Monte Carlo bakes of one scene and
// settings (the CPU and lavapipe, or two seeds) agree within the noise their probes report, while a
// wrong bake (fewer bounces, a brighter light) fails. The value-by-value comparison cannot tell
// them apart: two seeds differ far beyond its default tolerance.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/vulkan/cli_vk_util.h"

namespace gibake::test {
namespace {

using nlohmann::json;

const std::string kSampleDir = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell";
const std::string kSettings = " --ddgi --probe-counts 3,3,3 --rays 1024 --target-error 0 --relocate off"
                              " --reconstruction-check off --progress lines";

class VerifyStatistical : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir("verify_statistical");
    ASSERT_EQ(bake(kSampleDir + "/cornell.gltf", "ref.gibake", " --backend cpu --seed 0 --bounces 2"), 0);
  }
  static void TearDownTestSuite() {
    delete scratch_;
    scratch_ = nullptr;
  }
  static std::string path(const std::string& name) { return scratch_->path(name); }
  static int bake(const std::string& scene, const std::string& out, const std::string& extra) {
    const CliResult r = run_gibake_cli(shell_quote(scene) + kSettings + extra + " --out " + shell_quote(path(out)));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.exit_code;
  }
  // `verify FILE --against ref.gibake --compare statistical`: its report; names the failing checks.
  static json compare(const std::string& file, int expect_exit, std::string* failed = nullptr) {
    const CliResult r = run_gibake_cli("verify " + shell_quote(path(file)) + " --against " +
                                       shell_quote(path("ref.gibake")) + " --compare statistical --format json");
    EXPECT_EQ(r.exit_code, expect_exit) << file << "\n" << r.out << r.err;
    const json report = json::parse(r.out, nullptr, false);
    for (const json& c : report["checks"])
      if (c["status"] == "fail" && failed) *failed += c["name"].get<std::string>() + " ";
    return report;
  }
  static ScratchDir* scratch_;
};
ScratchDir* VerifyStatistical::scratch_ = nullptr;

TEST_F(VerifyStatistical, AnotherSeedPassesAndIsFarBeyondTheValueTolerance) {
  ASSERT_EQ(bake(kSampleDir + "/cornell.gltf", "seed1.gibake", " --backend cpu --seed 1 --bounces 2"), 0);
  const json report = compare("seed1.gibake", 0);
  EXPECT_EQ(report["compare"], "statistical");
  bool judged = false;
  for (const json& c : report["checks"])
    if (c["name"] == "against.ddgi[0].sh_irradiance") {
      judged = true;
      EXPECT_GT(c["details"]["items"].get<int>(), 0);
      EXPECT_GT(c["details"]["score_median"].get<double>(), 0.0);  // the seeds differ: verify saw noise
    }
  EXPECT_TRUE(judged) << report.dump();
  for (const char* tolerance : {"1e-4", "1"})
    EXPECT_EQ(run_gibake_cli("verify " + shell_quote(path("seed1.gibake")) + " --against " +
                             shell_quote(path("ref.gibake")) + " --tolerance " + tolerance)
                  .exit_code,
              7)
        << tolerance;
}

TEST_F(VerifyStatistical, LavapipeBakesPassAgainstTheCpuBake) {
  if (!have_vk_device(&vk::DeviceInfo::is_lavapipe)) GTEST_SKIP() << "lavapipe is not installed (mesa-vulkan-drivers)";
  ASSERT_EQ(bake(kSampleDir + "/cornell.gltf", "vk0.gibake", " --backend vulkan --vulkan-device lavapipe --seed 0 --bounces 2"), 0);
  ASSERT_EQ(bake(kSampleDir + "/cornell.gltf", "vk1.gibake", " --backend vulkan --vulkan-device lavapipe --seed 1 --bounces 2"), 0);
  compare("vk0.gibake", 0);  // the same seed on another backend
  compare("vk1.gibake", 0);  // another seed and backend
}

TEST_F(VerifyStatistical, WrongBakesFail) {
  // One bounce fewer: the indirect light is short everywhere.
  ASSERT_EQ(bake(kSampleDir + "/cornell.gltf", "bounces1.gibake", " --backend cpu --seed 1 --bounces 1"), 0);
  std::string failed;
  compare("bounces1.gibake", 7, &failed);
  EXPECT_NE(failed.find("against.ddgi[0].irradiance_bias"), std::string::npos) << failed;
  // The scene's light 20% brighter.
  json gltf = json::parse(std::ifstream(kSampleDir + "/cornell.gltf"));
  auto& intensity = gltf["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"];
  intensity = 1.2 * intensity.get<double>();
  std::filesystem::copy_file(kSampleDir + "/cornell.bin", path("cornell.bin"));
  std::ofstream(path("bright.gltf")) << gltf.dump();
  ASSERT_EQ(bake(path("bright.gltf"), "bright.gibake", " --backend cpu --seed 1 --bounces 2"), 0);
  failed.clear();
  compare("bright.gibake", 7, &failed);
  EXPECT_NE(failed.find("against.ddgi[0].irradiance_bias"), std::string::npos) << failed;
}

TEST_F(VerifyStatistical, OptionsOnlyWithTheMode) {
  const CliResult r = run_gibake_cli("verify " + shell_quote(path("ref.gibake")) + " --against " +
                                     shell_quote(path("ref.gibake")) + " --sigmas 3");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("--compare statistical"), std::string::npos) << r.err;
  compare("ref.gibake", 0);  // a file against itself
}

}  // namespace
}  // namespace gibake::test
