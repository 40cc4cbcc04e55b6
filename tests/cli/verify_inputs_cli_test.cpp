// `verify` says what it did not check (and --require fails on it); staleness by the scene's content,
// naming what changed and in which file, while a file re-saved with the same content stays fresh
// (a bake from before content hashing: tests/loader/verify_cli_test.cpp). A bake without light says
// "skipped" where it measured nothing; `preview --reference` needs no bake.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;
using nlohmann::json;

const std::string kSampleDir = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell";
const std::string kBake = " --ddgi --probe-counts 2,2,2 --rays 32 --bounces 1 --target-error 0 --relocate off"
                          " --reconstruction-check off --progress lines";

class VerifyInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* f : {"cornell.gltf", "cornell.bin"}) fs::copy_file(kSampleDir + "/" + f, scratch_.path(f));
  }
  std::string q(const std::string& name) const { return shell_quote(scratch_.path(name)); }
  json gltf() const { return json::parse(read_text_file(scratch_.path("cornell.gltf"))); }
  void write_gltf(const json& j, int indent) const { std::ofstream(scratch_.path("cornell.gltf")) << j.dump(indent); }
  // The report of `verify` and the check named `name` in it.
  static json check(const json& report, const std::string& name) {
    for (const json& c : report["checks"])
      if (c["name"] == name) return c;
    return json();
  }
  json verify_json(const std::string& args, int expect_exit) const {
    const CliResult r = run_gibake_cli("verify " + q("c.gibake") + " " + args + " --format json");
    EXPECT_EQ(r.exit_code, expect_exit) << args << "\n" << r.out << r.err;
    return json::parse(r.out, nullptr, false);
  }
  ScratchDir scratch_{"verify_inputs"};
};

// Without --scene the scene's checks are listed as skipped, with the reason, in text and JSON;
// --require fails (exit 7, result incomplete) when a required kind did not run.
TEST_F(VerifyInputs, ChecksThatDidNotRunAreListedAndCanBeRequired) {
  ASSERT_EQ(run_gibake_cli(q("cornell.gltf") + kBake + " --out " + q("c.gibake")).exit_code, 0);
  const CliResult text = run_gibake_cli("verify " + q("c.gibake"));
  EXPECT_EQ(text.exit_code, 0) << text.out << text.err;
  EXPECT_NE(text.out.find("skip  staleness: needs --scene"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find(": ok (not checked: against, staleness, lit, energy_bound, reconstruction)"),
            std::string::npos)
      << text.out;

  json report = verify_json("", 0);
  EXPECT_EQ(report["skipped"], json({"against", "staleness", "lit", "energy_bound", "reconstruction"}));
  for (const char* name : {"staleness", "lit", "energy_bound"}) EXPECT_EQ(check(report, name)["status"], "skip");

  report = verify_json("--require scene", 7);
  EXPECT_EQ(report["result"], "incomplete");
  EXPECT_EQ(report["require"], json({"staleness", "lit", "energy"}));
  EXPECT_EQ(check(report, "require.staleness")["status"], "fail");
  EXPECT_NE(check(report, "require.energy")["message"].get<std::string>().find("needs --scene"), std::string::npos);

  report = verify_json("--require scene,against --scene " + q("cornell.gltf") + " --against " + q("c.gibake"), 0);
  EXPECT_EQ(report["result"], "ok");
  EXPECT_EQ(check(report, "staleness")["status"], "pass");
  EXPECT_EQ(report["skipped"], json({"reconstruction"}));
  report = verify_json("--require all --scene " + q("cornell.gltf"), 7);
  EXPECT_EQ(check(report, "require.against")["status"], "fail");
  EXPECT_EQ(check(report, "require.reconstruction")["status"], "fail");
  EXPECT_TRUE(check(report, "require.staleness").is_null());

  const CliResult bad = run_gibake_cli("verify " + q("c.gibake") + " --require everything");
  EXPECT_EQ(bad.exit_code, 1) << bad.err;
  EXPECT_NE(bad.err.find("--require"), std::string::npos) << bad.err;
}

// Staleness hashes what the bake reads: the .gltf re-serialised with the same content is fresh
// (the re-saved file named); a changed light or a changed buffer is stale, naming the part and file.
TEST_F(VerifyInputs, StalenessNamesWhatChangedAndWhere) {
  ASSERT_EQ(run_gibake_cli(q("cornell.gltf") + kBake + " --out " + q("c.gibake")).exit_code, 0);
  const std::string scene = " --scene " + q("cornell.gltf");
  json report = verify_json(scene, 0);
  EXPECT_EQ(check(report, "staleness")["details"]["hashed"], "content");

  const json original = gltf();
  write_gltf(original, 1);  // other bytes, the same content
  ASSERT_NE(read_text_file(scratch_.path("cornell.gltf")), read_text_file(kSampleDir + "/cornell.gltf"));
  report = verify_json(scene, 0);
  json st = check(report, "staleness");
  EXPECT_EQ(st["status"], "pass");
  EXPECT_EQ(st["details"]["files_changed"], json({"cornell.gltf (scene)"}));
  EXPECT_NE(st["message"].get<std::string>().find("re-saved"), std::string::npos) << st.dump();
  const CliResult preview = run_gibake_cli("preview " + q("cornell.gltf") + " --bake " + q("c.gibake") +
                                           " --size 16x9 --out " + q("v.png"));
  EXPECT_EQ(preview.exit_code, 0) << preview.err;

  json brighter = original;
  brighter["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = 4.0;
  write_gltf(brighter, 2);
  const CliResult text = run_gibake_cli("verify " + q("c.gibake") + scene);
  EXPECT_EQ(text.exit_code, 7) << text.out;
  EXPECT_NE(text.out.find("fail  staleness: stale: " + scratch_.path("cornell.gltf") +
                          ": the scene's lights changed since the bake (files changed: cornell.gltf (scene))"),
            std::string::npos)
      << text.out;
  report = verify_json(scene, 7);
  EXPECT_EQ(check(report, "staleness")["details"]["parts_changed"], json({"lights"}));

  fs::copy_file(kSampleDir + "/cornell.gltf", scratch_.path("cornell.gltf"), fs::copy_options::overwrite_existing);
  std::string bin = read_text_file(scratch_.path("cornell.bin"));
  bin[4] = char(bin[4] ^ 0x10);  // a bit of the first vertex's x
  std::ofstream(scratch_.path("cornell.bin"), std::ios::binary) << bin;
  report = verify_json(scene, 7);
  st = check(report, "staleness");
  EXPECT_EQ(st["details"]["parts_changed"], json({"geometry"}));
  EXPECT_EQ(st["details"]["files_changed"], json({"cornell.bin (buffer)"})) << st.dump();
  EXPECT_NE(st["message"].get<std::string>().find("geometry changed"), std::string::npos) << st.dump();
}

// A bake of a scene without any light: black, with a warning; where the summary measured nothing
// (the adaptive rays' error, the reconstruction check) it says skipped, and why, not figures of nothing.
TEST(BakeSummary, ABakeWithoutLightSaysSkippedWhereNothingWasMeasured) {
  ScratchDir scratch("summary_unlit");  // a Khronos test asset without lights
  const CliResult r = run_gibake_cli(shell_quote(std::string(GIBAKE_ASSETS_DIR) + "/texture-transform-test/TextureTransformTest.gltf") +
                                     " --ddgi --rays 32 --max-rays 64 --ray-budget 32 --check-patches 16 --out " +
                                     shell_quote(scratch.path("box.gibake")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("gibake: warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("adaptive rays: skipped: no active probe received light, so no error was measured"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("reached the target error"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("patches of 4x4 points): skipped: no patch's path-traced reference is lit"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("within 10%"), std::string::npos) << r.err;
}

// `preview --reference` renders the path-traced reference from the scene alone (lights: the scene's,
// --sun and --sky); a lit view still needs the bake.
TEST(PreviewReference, NeedsNoBake) {
  ScratchDir scratch("preview_reference");
  const std::string sample = shell_quote(kSampleDir + "/cornell.gltf");
  const CliResult r = run_gibake_cli("preview " + sample + " --reference --spp 2 --size 32x18 --out " +
                                     shell_quote(scratch.path("ref.exr")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(scratch.path("ref.exr")));
  const CliResult lit = run_gibake_cli("preview " + sample + " --size 32x18 --out " + shell_quote(scratch.path("l.png")));
  EXPECT_EQ(lit.exit_code, 1) << lit.err;
  EXPECT_NE(lit.err.find("needs the bake file"), std::string::npos) << lit.err;
  const CliResult diff = run_gibake_cli("preview " + sample + " --reference --diff " + shell_quote(scratch.path("d.png")) +
                                        " --size 32x18 --out " + shell_quote(scratch.path("r2.exr")));
  EXPECT_EQ(diff.exit_code, 1) << diff.err;
}

}  // namespace
