// `gibake inspect` end to end: exit codes, stdout JSON, one-line errors on stderr.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

using nlohmann::json;

using RunResult = gibake::test::CliResult;

std::string temp_path(const std::string& name) {
  return (gibake::test::process_tmp() / ("inspect_cli_" + name)).string();
}

RunResult run_gibake(const std::string& args) { return gibake::test::run_gibake_cli(args); }
std::string quoted(const std::string& s) { return gibake::test::shell_quote(s); }
std::vector<std::string> lines(const std::string& text) { return gibake::test::split_lines(text); }

std::string asset(const std::string& relative) {
  return std::string(GIBAKE_ASSETS_DIR) + "/" + relative;
}

// Every stderr line is a warning (no errors, no stray output).
void expect_only_warnings(const std::string& err) {
  for (const std::string& line : lines(err))
    EXPECT_EQ(line.rfind("gibake: warning: ", 0), 0u) << line;
}

// Exactly one stderr line: "gibake: error: ..." naming `file`.
void expect_one_error_line(const RunResult& r, const std::string& file) {
  const std::vector<std::string> v = lines(r.err);
  ASSERT_EQ(v.size(), 1u) << r.err;
  EXPECT_EQ(v[0].rfind("gibake: error: ", 0), 0u) << v[0];
  EXPECT_NE(v[0].find(file), std::string::npos) << v[0];
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(InspectCli, BoxJson) {
  const RunResult r = run_gibake("inspect " + quoted(asset("box/Box.gltf")) + " --format json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_only_warnings(r.err);
  const json j = json::parse(r.out);
  EXPECT_EQ(j["triangles"], 12);
  EXPECT_EQ(j["diagnostics"]["closed_components"], 1);
  EXPECT_EQ(j["diagnostics"]["border_edges"], 0);
  EXPECT_TRUE(j["materials"].is_array());
  EXPECT_TRUE(j["lights"].is_array());
}

TEST(InspectCli, BoxText) {
  const RunResult r = run_gibake("inspect " + quoted(asset("box/Box.gltf")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("triangles: 12"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("diagnostics:"), std::string::npos) << r.out;
}

TEST(InspectCli, SampleSceneJson) {
  const std::string sample = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  const RunResult r =
      run_gibake("inspect " + quoted(sample) + " --format json --check-self-intersections");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_only_warnings(r.err);
  const json j = json::parse(r.out);
  EXPECT_EQ(j["triangles"], 36);
  ASSERT_EQ(j["lights"].size(), 1u);
  EXPECT_EQ(j["lights"][0]["type"], "point");
  EXPECT_EQ(j["lights"][0]["unit"], "cd");
  EXPECT_EQ(j["diagnostics"]["closed_components"], 2);
  EXPECT_EQ(j["diagnostics"]["self_intersecting_pairs"], 0);
}

TEST(InspectCli, GarbageFileIsInvalidInput) {
  const std::string path = temp_path("broken.gltf");
  std::ofstream(path) << "{ this is not json";
  const RunResult r = run_gibake("inspect " + quoted(path) + " --format json");
  std::remove(path.c_str());
  EXPECT_EQ(r.exit_code, 3) << r.err;
  expect_one_error_line(r, "broken.gltf");
}

TEST(InspectCli, IndexOutOfRangeIsInvalidInput) {
  const RunResult r =
      run_gibake("inspect " + quoted(asset("malformed/IndexOutOfRange/IndexOutOfRange.gltf")) +
                 " --format json");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  expect_one_error_line(r, "IndexOutOfRange.gltf");
}

TEST(InspectCli, MissingFileIsIoFailure) {
  const RunResult r = run_gibake("inspect " + quoted(temp_path("no_such_scene.gltf")));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  expect_one_error_line(r, "no_such_scene.gltf");
}

TEST(InspectCli, BadArguments) {
  EXPECT_EQ(run_gibake("inspect").exit_code, 1);
  EXPECT_EQ(run_gibake("inspect " + quoted(asset("box/Box.gltf")) + " --format xml").exit_code, 1);
}

}  // namespace
