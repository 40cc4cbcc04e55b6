// `gibake verify`: self comparison, a changed probe named, sanity failures, exit codes.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "io/bakefile/bake_file.h"
#include "io/gltf/import.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;

class VerifyCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir("verify");
    result_ = test::make_ddgi(3, 2, 2, 2, 31);
    ASSERT_TRUE(write(result_, "ref.bin").is_ok());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  Status write(const DdgiResult& r, const std::string& name) {
    BakeOutputs outputs;
    outputs.ddgi = &r;
    return write_bake_file(dir_ + "/" + name, outputs, BakeFileOptions{}, {});
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
  DdgiResult result_;
};

TEST_F(VerifyCli, SelfComparisonPasses) {
  const test::RunResult run = test::run_gibake_stdout("verify " + path("ref.bin") + " --against " + path("ref.bin") +
                                                      " --format json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  EXPECT_EQ(report["result"], "ok");
  EXPECT_EQ(report["exit_code"], 0);
  bool compared = false;
  for (const auto& c : report["checks"]) compared |= c["name"] == "against.ddgi[0].sh_irradiance";
  EXPECT_TRUE(compared);
  EXPECT_EQ(test::run_gibake("verify " + path("ref.bin")).exit_code, 0);
}

TEST_F(VerifyCli, ChangedProbeIsNamed) {
  DdgiResult changed = result_;
  changed.sh[(7 * 9 + 0) * 3 + 1] *= 1.01f;  // probe 7, L00 green, +1%
  ASSERT_TRUE(write(changed, "changed.bin").is_ok());
  test::RunResult run = test::run_gibake("verify " + path("changed.bin") + " --against " + path("ref.bin"));
  EXPECT_EQ(run.exit_code, 7) << run.out;
  EXPECT_NE(run.out.find("probe 7 differs"), std::string::npos) << run.out;
  run = test::run_gibake_stdout("verify " + path("changed.bin") + " --against " + path("ref.bin") + " --format json");
  EXPECT_EQ(run.exit_code, 7);
  const nlohmann::json report = nlohmann::json::parse(run.out);
  EXPECT_EQ(report["result"], "differs");
  for (const auto& c : report["checks"])
    if (c["name"] == "against.ddgi[0].sh_irradiance") {
      EXPECT_EQ(c["status"], "fail");
      EXPECT_EQ(c["details"]["worst_probe"], 7);
    }
  // Within a loose tolerance the same files agree.
  EXPECT_EQ(test::run_gibake("verify " + path("changed.bin") + " --against " + path("ref.bin") + " --tolerance 0.05")
                .exit_code,
            0);
}

// `verify` checks every byte: a non-zero padding byte after the metadata (the file's last
// section) or a byte appended after its padded end makes the file invalid, naming the offset.
TEST_F(VerifyCli, PaddingAndTrailingBytesAreInvalid) {
  std::vector<uint8_t> bytes;
  loader::BakeFile file;
  for (std::string tool = "x"; tool.size() < 17; tool += "x") {  // a metadata length that needs padding
    BakeOutputs outputs;
    outputs.ddgi = &result_;
    outputs.metadata_json = R"({"tool":")" + tool + R"("})";
    ASSERT_TRUE(write_bake_file(path("ref.bin"), outputs, BakeFileOptions{}, {}).is_ok());
    bytes = test::read_bytes(path("ref.bin"));
    ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
    if ((file.sections().back().offset + file.sections().back().size) % 16 != 0) break;
  }
  const gibake_section_entry meta = file.sections().back();
  ASSERT_EQ(meta.type, uint32_t(GIBAKE_SECTION_METADATA));
  const uint64_t end = meta.offset + meta.size;
  EXPECT_EQ(test::run_gibake("verify " + path("ref.bin")).exit_code, 0);  // untouched: passes
  ASSERT_LT(end, bytes.size()) << "this file's metadata needs padding (its JSON length is not a multiple of 16)";
  {
    std::vector<uint8_t> bad = bytes;
    bad[end] = 0x20;
    test::write_bytes(path("padding.bin"), bad);
    const test::RunResult run = test::run_gibake("verify " + path("padding.bin"));
    EXPECT_EQ(run.exit_code, 3) << run.out;
    EXPECT_NE(run.out.find("bad_padding"), std::string::npos) << run.out;
    EXPECT_NE(run.out.find("non-zero padding byte 0x20 at offset " + std::to_string(end) +
                           " (padding after section " + std::to_string(file.sections().size() - 1) + " (metadata))"),
              std::string::npos)
        << run.out;
  }
  std::vector<uint8_t> longer = bytes;
  longer.resize(bytes.size() + 16, 0);
  gibake_file_header h;
  std::memcpy(&h, longer.data(), sizeof h);
  h.file_size = longer.size();
  std::memcpy(longer.data(), &h, sizeof h);
  test::reseal(longer);
  test::write_bytes(path("trailing.bin"), longer);
  const test::RunResult run = test::run_gibake("verify " + path("trailing.bin") + " --format json");
  EXPECT_EQ(run.exit_code, 3) << run.out;
  EXPECT_NE(run.out.find("16 bytes at offset " + std::to_string(bytes.size())), std::string::npos) << run.out;
}

TEST_F(VerifyCli, NanAndNegativeIrradianceAreInvalid) {
  DdgiResult bad = result_;
  bad.sh[40] = std::nanf("");
  ASSERT_TRUE(write(bad, "nan.bin").is_ok());
  test::RunResult run = test::run_gibake("verify " + path("nan.bin"));
  EXPECT_EQ(run.exit_code, 3) << run.out;
  EXPECT_NE(run.out.find("NaN"), std::string::npos);
  bad = result_;
  bad.irradiance_atlas[4 * 17] = -2.f;
  ASSERT_TRUE(write(bad, "neg.bin").is_ok());
  run = test::run_gibake("verify " + path("neg.bin"));
  EXPECT_EQ(run.exit_code, 3) << run.out;
  EXPECT_NE(run.out.find("negative"), std::string::npos);
}

TEST_F(VerifyCli, MissingFileIsIoFailureAndStructureMismatchDiffers) {
  EXPECT_EQ(test::run_gibake("verify " + path("absent.bin")).exit_code, 2);
  EXPECT_EQ(test::run_gibake("verify " + dir_).exit_code, 2);  // a folder, not a file
  EXPECT_EQ(test::run_gibake("info " + dir_).exit_code, 2);
  EXPECT_EQ(test::run_gibake("verify " + path("ref.bin") + " --against " + path("absent.bin")).exit_code, 2);
  ASSERT_TRUE(write(test::make_ddgi(2, 2, 2, 2, 3), "other.bin").is_ok());
  EXPECT_EQ(test::run_gibake("verify " + path("other.bin") + " --against " + path("ref.bin")).exit_code, 7);
}

TEST_F(VerifyCli, RingingIsReported) {
  const test::RunResult run = test::run_gibake_stdout("verify " + path("ref.bin") + " --format json");
  const nlohmann::json report = nlohmann::json::parse(run.out);
  bool found = false;
  for (const auto& c : report["checks"])
    if (c["name"] == "ddgi[0].sh_ringing") {
      found = true;
      EXPECT_TRUE(c["details"].contains("worst_negative_relative"));
    }
  EXPECT_TRUE(found);
}

}  // namespace

namespace {

using namespace gibake;

// --scene: a bake whose input hash matches the scene and settings is fresh; changed settings
// are stale (exit 7); irradiance far above what the scene's emitters can deliver fails.
TEST(VerifyScene, StalenessAndEnergyBound) {
  const std::string scene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  if (!std::filesystem::exists(scene)) GTEST_SKIP() << "no sample scene " << scene;
  Scene imported;
  ASSERT_TRUE(import_scene(scene, ImportOptions{}, Context{}, imported).is_ok());
  const std::string dir = test::scratch_dir("scene");
  DdgiResult r = test::make_ddgi(2, 2, 2, 1, 51, false);
  for (float& v : r.sh) v *= 1e-3f;  // dim: well inside any bound
  BakeOutputs outputs;
  outputs.ddgi = &r;
  ASSERT_TRUE(hash_inputs(imported.input_files, r.settings_json, outputs.input_hash).is_ok());
  ASSERT_TRUE(write_bake_file(dir + "/fresh.bin", outputs, BakeFileOptions{}, imported.input_files).is_ok());
  test::RunResult run = test::run_gibake("verify " + dir + "/fresh.bin --scene " + scene);
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("pass  staleness"), std::string::npos) << run.out;

  r.settings_json = R"({"rays_per_probe":512,"sh_order":1})";  // settings changed after hashing
  ASSERT_TRUE(write_bake_file(dir + "/stale.bin", outputs, BakeFileOptions{}, {}).is_ok());
  run = test::run_gibake("verify " + dir + "/stale.bin --scene " + scene);
  EXPECT_EQ(run.exit_code, 7) << run.out;
  EXPECT_NE(run.out.find("fail  staleness"), std::string::npos) << run.out;

  r = test::make_ddgi(2, 2, 2, 1, 51, false);
  for (float& v : r.sh) v *= 1e7f;
  ASSERT_TRUE(hash_inputs(imported.input_files, r.settings_json, outputs.input_hash).is_ok());
  ASSERT_TRUE(write_bake_file(dir + "/hot.bin", outputs, BakeFileOptions{}, {}).is_ok());
  run = test::run_gibake("verify " + dir + "/hot.bin --scene " + scene + " --format json");
  EXPECT_EQ(run.exit_code, 7) << run.out;
  EXPECT_NE(run.out.find("exceeds the scene's bound"), std::string::npos) << run.out;
  std::filesystem::remove_all(dir);
}

}  // namespace
