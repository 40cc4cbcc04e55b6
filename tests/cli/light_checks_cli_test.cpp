// verify --scene fails a black bake of a lit scene; the energy bound uses the
// albedos the triangles really have; an ignored material extension that changes light transport is
// named once; the black-bake hint names the real cause when --sun was given; preview --diff says
// how its two figures are normalised.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file, ScratchDir
using json = nlohmann::json;

const std::string kSampleDir = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell";
const std::string kToyCar = std::string(GIBAKE_ASSETS_DIR) + "/toy-car/ToyCar.gltf";

class LightChecks : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return scratch_.path(name); }
  ScratchDir scratch_{"light_checks"};
};

// The check named `name` in verify's JSON report.
json check_named(const json& report, const std::string& name) {
  for (const json& c : report["checks"])
    if (c["name"] == name) return c;
  return json();
}

TEST_F(LightChecks, BlackBakeOfALitSceneFailsVerify) {
  // One probe at the centre of the 7 cm car, inside it (the default grid fits the model).
  const std::string out = path("car.gibake");
  const CliResult bake = run_gibake_cli(shell_quote(kToyCar) + " --ddgi --probe-counts 1,1,1 --rays 32 --bounces 0 --sun 0.3,-1,0.2:100000 "
                                        "--progress lines --out " + shell_quote(out));
  ASSERT_EQ(bake.exit_code, 0) << bake.err;
  // The hint names the light the scene has and where the probe is, not "add --sun".
  EXPECT_NE(bake.err.find("black everywhere although the scene has light (--sun"), std::string::npos) << bake.err;
  EXPECT_EQ(bake.err.find("add --sun"), std::string::npos) << bake.err;
  // The glass, named once (traced as thin pass-through).
  const size_t first = bake.err.find("KHR_materials_transmission is partly supported");
  ASSERT_NE(first, std::string::npos) << bake.err;
  EXPECT_EQ(bake.err.find("KHR_materials_transmission", first + 1), std::string::npos) << bake.err;
  const CliResult verify = run_gibake_cli("verify " + shell_quote(out) + " --scene " + shell_quote(kToyCar) +
                                          " --format json");
  EXPECT_EQ(verify.exit_code, 7) << verify.out;
  const json lit = check_named(json::parse(verify.out), "lit");
  EXPECT_EQ(lit["status"], "fail") << lit.dump();
  EXPECT_EQ(lit["details"]["lit_probes"], 0);
}

TEST_F(LightChecks, EnergyBoundFromTheAlbedosInUse) {
  // The sample plus one material no triangle uses, white by default: the bound must still hold
  // with the used albedos (at most 0.75): an unused white material must not make it give up.
  json doc = json::parse(read_text_file(kSampleDir + "/cornell.gltf"));
  doc["materials"].push_back({{"name", "unused white"}});
  std::ofstream(path("cornell.gltf")) << doc.dump();
  fs::copy_file(kSampleDir + "/cornell.bin", path("cornell.bin"));
  const std::string out = path("c.gibake");
  ASSERT_EQ(run_gibake_cli(shell_quote(path("cornell.gltf")) + " --ddgi --rays 64 --bounces 2 --out " +
                           shell_quote(out)).exit_code,
            0);
  const CliResult verify = run_gibake_cli("verify " + shell_quote(out) + " --scene " +
                                          shell_quote(path("cornell.gltf")) + " --format json");
  EXPECT_EQ(verify.exit_code, 0) << verify.out;
  const json report = json::parse(verify.out);
  const json energy = check_named(report, "energy_bound");
  EXPECT_EQ(energy["status"], "pass") << energy.dump();
  EXPECT_NEAR(energy["details"]["max_albedo"].get<double>(), 0.75, 1e-6) << energy.dump();
  EXPECT_EQ(check_named(report, "lit")["status"], "pass");
}

TEST_F(LightChecks, DiffSaysHowItsFiguresAreNormalised) {
  const std::string out = path("s.gibake");
  const std::string sample = shell_quote(kSampleDir + "/cornell.gltf");
  ASSERT_EQ(run_gibake_cli(sample + " --ddgi --rays 32 --bounces 1 --out " + shell_quote(out)).exit_code, 0);
  const CliResult r = run_gibake_cli("preview " + sample + " --bake " + shell_quote(out) + " --size 48x27 --spp 2 --out " +
                                     shell_quote(path("ref.png")) + " --reference --diff " + shell_quote(path("d.png")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("relative RMS"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("sum ref^2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/ ref, every pixel weighs the same"), std::string::npos) << r.out;
}

// A scene whose triangles have no area (glTF allows them: inspect reads it) has nothing to light
// or to place probes by: a bake refuses it as it refuses a scene without triangles, exit 3.
TEST_F(LightChecks, ASceneOfZeroAreaTrianglesHasNothingToBake) {
  const json scene = {{"asset", {{"version", "2.0"}}},
                      {"buffers",
                       {{{"byteLength", 36},
                         {"uri",
                          "data:application/octet-stream;base64,"
                          "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAQAAAAAAAAAAA"}}}},
                      {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
                      {"accessors",
                       {{{"bufferView", 0},
                         {"componentType", 5126},
                         {"count", 3},
                         {"type", "VEC3"},
                         {"min", {0, 0, 0}},
                         {"max", {2, 0, 0}}}}},
                      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
                      {"nodes", {{{"mesh", 0}}}},
                      {"scenes", {{{"nodes", {0}}}}},
                      {"scene", 0}};
  const std::string gltf = path("line.gltf"), out = path("line.gibake");
  std::ofstream(gltf) << scene.dump();
  EXPECT_EQ(run_gibake_cli("inspect " + shell_quote(gltf)).exit_code, 0);
  const CliResult bake = run_gibake_cli(shell_quote(gltf) + " --ddgi --sky 1,1,1 --out " + shell_quote(out));
  EXPECT_EQ(bake.exit_code, 3) << bake.err;
  EXPECT_EQ(
      split_lines(bake.err).back(),
      "gibake: error: " + gltf +
          ": scene: no triangle has an area (every one is a point or a line): nothing to light or place probes by");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
