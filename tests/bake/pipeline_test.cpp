// The library runs a whole bake request (bake/pipeline/bake_request.h): the file it writes loads and
// holds the bytes `gibake bake` writes for the same settings, and a failing request says why and
// writes nothing.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "bake/pipeline/bake_request.h"
#include "gibake/loader.hpp"

namespace fs = std::filesystem;
using namespace gibake;

namespace {

std::vector<char> read_all(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("gibake_pipeline_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

const std::string kScene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";

// The request `gibake <scene> --ddgi --lpv --rays 32 --target-error 0 --ray-budget 0 --backend cpu`
// makes: the CLI's defaults where they differ from the settings structs'.
BakeRequest small_request(const fs::path& out) {
  BakeRequest r;
  r.files.scene = kScene;
  r.files.out = out.string();
  r.ddgi = true;
  r.lpv = true;
  DdgiSettings& s = r.ddgi_settings;
  s.rays = 32;
  s.target_error = 0.f;
  s.ray_budget = 0;
  s.grid.max_probes = uint64_t(1) << 21;
  s.grid.auto_max_probes = 32768;
  s.backend.backend = Backend::Cpu;
  s.filter.enabled = false;  // the CLI's default level leaves the probes unfiltered (bake/ddgi/quality.h)
  s.fit.enabled = true;      // ... and fits the atlases to the surfaces, 262144 points of 144 paths
  r.lpv_settings.resolution = 32;
  r.lpv_settings.iterations = 0;
  r.lpv_settings.cascades = 1;
  r.lpv_settings.vpl_samples = r.lpv_settings.emissive_samples = 65536;
  r.check.patches = 16;
  r.check.rays = 16;
  return r;
}

TEST(Pipeline, RunsAWholeRequestToTheCliBytes) {
  const fs::path dir = scratch("whole");
  const fs::path lib_out = dir / "library.gibake", cli_out = dir / "cli.gibake";
  std::unique_ptr<BakeResult> result;
  const Status st = run_bake(small_request(lib_out), Context{}, result);
  ASSERT_TRUE(st) << st.message();
  ASSERT_TRUE(result);
  EXPECT_GT(result->ddgi_report().active, 0);
  EXPECT_FALSE(result->lpv.cascades.empty());
  EXPECT_TRUE(result->have_reconstruction);  // the check read the written bytes
  EXPECT_TRUE(result->have_leak_audit);
  EXPECT_TRUE(result->have_surface_fit);

  loader::BakeFile file;
  const loader::Error e = file.open(lib_out.string());
  ASSERT_FALSE(e) << e.message;
  ASSERT_GE(file.ddgi_volumes().size(), 1u);  // the default grid, then the refined volumes
  EXPECT_EQ(file.ddgi_volumes().size(), result->volumes.size());
  EXPECT_EQ(file.ddgi_volumes()[0].probe_count(), uint32_t(result->ddgi_report().probes));
  EXPECT_EQ(file.lpv_cascades().size(), 1u);

  const std::string cmd = std::string(GIBAKE_EXE) + " '" + kScene + "' --ddgi --lpv --rays 32 --target-error 0 " +
                          "--ray-budget 0 --backend cpu --check-patches 16 --check-rays 16 --out '" +
                          cli_out.string() + "' > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::vector<char> lib = read_all(lib_out), cli = read_all(cli_out);
  ASSERT_FALSE(lib.empty());
  EXPECT_TRUE(lib == cli) << "the library's file (" << lib.size() << " bytes) differs from the CLI's (" << cli.size()
                          << " bytes)";
  fs::remove_all(dir);
}

TEST(Pipeline, FailingRequestSaysWhyAndWritesNothing) {
  const fs::path dir = scratch("missing");
  BakeRequest r = small_request(dir / "never.gibake");
  r.files.scene = (dir / "no_such_scene.gltf").string();
  std::unique_ptr<BakeResult> result;
  const Status st = run_bake(r, Context{}, result);
  EXPECT_FALSE(st);
  EXPECT_EQ(st.code(), ExitCode::IoFailure) << st.message();
  EXPECT_NE(st.message().find("no_such_scene.gltf"), std::string::npos) << st.message();
  EXPECT_FALSE(fs::exists(dir / "never.gibake"));
  fs::remove_all(dir);
}

}  // namespace
