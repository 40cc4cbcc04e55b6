// `--backend auto` (the default) through the CLI: on a machine without a Vulkan GPU (lavapipe at
// most, as in CI) it must bake exactly what `--backend cpu` bakes, byte for byte, and say why in the
// summary.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/vulkan/cli_vk_util.h"

namespace gibake::test {
namespace {

const std::string kSample = cornell_sample_arg();

std::string tmp(const std::string& name) { return vk_cli_tmp("gibake_vk_auto_", name); }

bool have_gpu() { return have_vk_device(&vk::DeviceInfo::is_gpu); }

// The summary object of a --progress json bake's stderr.
nlohmann::json summary_of(const std::string& err) {
  std::istringstream lines(err);
  for (std::string line; std::getline(lines, line);) {
    const auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object() && j.value("event", "") == "summary") return j;
  }
  return {};
}

TEST(BackendAutoCli, WithoutGpuBakesTheCpuBytes) {
  if (have_gpu()) GTEST_SKIP() << "a Vulkan GPU is present: auto follows the cost model (backend_cost_test)";
  const std::string cpu = tmp("cpu.gibake"), dflt = tmp("default.gibake"), automatic = tmp("auto.gibake");
  const std::string base = kSample + " --ddgi --rays 64 --bounces 2 --progress json";
  const CliResult rc = run_gibake_cli(base + " --backend cpu --threads 2 --out " + shell_quote(cpu));
  ASSERT_EQ(rc.exit_code, 0) << rc.err;
  const CliResult rd = run_gibake_cli(base + " --threads 2 --out " + shell_quote(dflt));  // auto is the default
  ASSERT_EQ(rd.exit_code, 0) << rd.err;
  const CliResult ra = run_gibake_cli(base + " --backend auto --threads 1 --out " + shell_quote(automatic));
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  const std::string want = read_text_file(cpu);
  ASSERT_GT(want.size(), 1000u);
  EXPECT_TRUE(read_text_file(dflt) == want) << "the default (auto) bake differs from --backend cpu";
  EXPECT_TRUE(read_text_file(automatic) == want) << "--backend auto differs from --backend cpu";
  const nlohmann::json s = summary_of(rd.err);
  ASSERT_TRUE(s.contains("backend")) << rd.err;
  EXPECT_EQ(s["backend"]["name"], "cpu");
  EXPECT_TRUE(s["backend"]["auto"].get<bool>());
  // This light bake is decided before the devices are listed (the CPU beats even a discrete GPU's
  // estimate); a heavier one on this machine would name the missing GPU and weigh nothing.
  const std::string reason = s["backend"]["reason"];
  EXPECT_NE(reason.find("a light bake: the CPU is estimated faster than any GPU would be"), std::string::npos)
      << reason;
  EXPECT_TRUE(s["backend"].contains("estimate_s"));
  const nlohmann::json sc = summary_of(rc.err);
  EXPECT_EQ(sc["backend"]["name"], "cpu");
  EXPECT_FALSE(sc["backend"]["auto"].get<bool>());
  for (const auto& f : {cpu, dflt, automatic}) std::filesystem::remove(f);
}

}  // namespace
}  // namespace gibake::test
