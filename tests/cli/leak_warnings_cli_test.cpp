// The leak audit warns only where active probes blend light across a wall. The
// bundled sample's default bake prints no warnings (its two thin-wall regions are the insides of
// its closed boxes, whose probes are inactive), and the JSON summary still lists both regions.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file

const std::string kSample = shell_quote(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf");

std::string out_file() {
  return (gibake::test::process_tmp() / "leak_cli.gibake").string();
}

TEST(LeakWarningsCli, SampleDefaultBakePrintsNoWarnings) {
  const CliResult r = run_gibake_cli(kSample + " --ddgi --progress lines --out " + shell_quote(out_file()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("leak audit: 2 thin-wall regions"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("0 of them with active probes blending across"), std::string::npos) << r.err;
  fs::remove(out_file());
}

TEST(LeakWarningsCli, JsonSummaryListsEveryRegion) {
  const CliResult r = run_gibake_cli(kSample + " --ddgi --progress json --out " + shell_quote(out_file()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json summary;
  for (const std::string& line : split_lines(r.err)) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object() && j.value("event", "") == "summary") summary = j;
  }
  ASSERT_TRUE(summary.contains("leak_audit")) << r.err;
  const nlohmann::json& leaks = summary["leak_audit"];
  EXPECT_EQ(leaks["regions"], 2);
  EXPECT_EQ(leaks["warned"], 0);
  ASSERT_EQ(leaks["region_list"].size(), 2u);
  for (const auto& region : leaks["region_list"]) {
    EXPECT_EQ(region["warned"], false);
    EXPECT_EQ(region["active_probes_across"], 0);
    EXPECT_EQ(region["min"].size(), 3u);
  }
  fs::remove(out_file());
}

TEST(LeakWarningsCli, InspectJsonListsEveryRegion) {
  const CliResult r = run_gibake_cli("inspect " + kSample + " --format json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("leak_audit")) << r.out;
  EXPECT_EQ(j["leak_audit"]["regions"], 2);
  EXPECT_EQ(j["leak_audit"]["region_list"].size(), 2u);
  EXPECT_EQ(j["triangles"], 36);  // the importer's report is unchanged beside it
}

}  // namespace
