// `gibake verify`: self comparison, a changed probe named, sanity failures, exit codes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "io/bakefile/bake_file.h"
#include "io/gltf/import.h"
#include "synthetic.h"
#include "test_util.h"
#include "tests/support/cli_run.h"

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
  // ref.bin with SH value `index` set to NaN and every checksum made to match: the writer refuses
  // NaN light, so such a file comes from elsewhere (a broken writer, an edit).
  void write_nan_sh(const std::string& name, size_t index, float value = std::nanf("")) {
    std::vector<uint8_t> bytes = test::read_bytes(path("ref.bin"));
    gibake_file_header h;
    std::memcpy(&h, bytes.data(), sizeof h);
    for (size_t i = 0; i < h.section_count; ++i) {
      gibake_section_entry* e = test::table_entry(bytes, i);
      if (e->type != GIBAKE_SECTION_DDGI_SH) continue;
      ASSERT_EQ(e->format, uint32_t(GIBAKE_FORMAT_F32));
      std::memcpy(bytes.data() + e->offset + index * sizeof(float), &value, sizeof value);
      e->checksum = loader::xxh64(bytes.data() + e->offset, size_t(e->size), GIBAKE_HASH_SEED);
    }
    test::reseal(bytes);
    test::write_bytes(path(name), bytes);
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

// The report follows docs/verify-report.schema.json: the schema is JSON a validator can load, the
// report has every key it requires, and every check's name is one the schema lists, on a bake with
// every kind of section checked against itself and its scene.
TEST_F(VerifyCli, ReportFollowsItsSchema) {
  std::ifstream in(std::string(GIBAKE_SOURCE_DIR) + "/docs/verify-report.schema.json");
  const nlohmann::json schema = nlohmann::json::parse(in, nullptr, false);
  ASSERT_FALSE(schema.is_discarded()) << "the schema is not JSON";
  const nlohmann::json& names = schema["properties"]["checks"]["items"]["properties"]["name"]["anyOf"];
  auto listed = [&names](const std::string& name) {
    for (const nlohmann::json& rule : names) {
      if (rule.contains("enum"))
        for (const nlohmann::json& e : rule["enum"])
          if (e == name) return true;
      if (rule.contains("pattern") && std::regex_search(name, std::regex(rule["pattern"].get<std::string>())))
        return true;
    }
    return false;
  };
  const std::string scene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf", bake = path("all.bin");
  ASSERT_EQ(test::run_gibake(scene +
                             " --ddgi --lpv --vxgi --quality draft --probe-counts 3,3,3 --rays 32 --lpv-res 8 "
                             "--vxgi-res 8 --vxgi-rays 2 --vxgi-calibrate 0 --reconstruction-check off --out " +
                             bake)
                .exit_code,
            0);
  const test::RunResult run =
      test::run_gibake_stdout("verify " + bake + " --against " + bake + " --scene " + scene +
                              " --max-reconstruction-error 10 --check-patches 4 --check-rays 16 "
                              "--format json");
  const nlohmann::json report = nlohmann::json::parse(run.out, nullptr, false);
  ASSERT_TRUE(report.is_object()) << run.out;
  for (const nlohmann::json& key : schema["required"]) EXPECT_TRUE(report.contains(key.get<std::string>())) << key;
  size_t checks = 0;
  for (const nlohmann::json& c : report["checks"]) {
    EXPECT_TRUE(listed(c["name"].get<std::string>())) << c["name"] << " is not in the schema";
    ++checks;
  }
  EXPECT_GT(checks, 20u);
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
  EXPECT_FALSE(write(bad, "refused.bin").is_ok());  // the writer refuses NaN light
  EXPECT_FALSE(std::filesystem::exists(path("refused.bin")));
  write_nan_sh("nan.bin", 40);
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

// A finite value so large that a sampler's weighted sums of it overflow (3e38: the SH's irradiance
// reads back infinite) is refused as a NaN is: by verify's finite check and by the readers.
TEST_F(VerifyCli, ValuesBeyondWhatSamplersSumAreRefused) {
  write_nan_sh("huge.bin", 0, 3e38f);
  std::ofstream(path("pts.csv")) << "0,0,0,0,1,0\n";
  test::RunResult run = test::run_gibake("verify " + path("huge.bin"));
  EXPECT_EQ(run.exit_code, 3) << run.out;
  EXPECT_NE(run.out.find("beyond 1e36"), std::string::npos) << run.out;
  run = test::run_gibake("sample " + path("huge.bin") + " --points " + path("pts.csv") + " --source ddgi");
  EXPECT_EQ(run.exit_code, 3) << run.out;
  EXPECT_NE(run.out.find("huge.bin: ddgi[0].sh probe 0: 1 value(s) NaN or infinite (or beyond 1e36"), std::string::npos)
      << run.out;
  EXPECT_EQ(run.out.find("inf"), run.out.find("infinite")) << run.out;  // no "inf" printed as a value
}

// A file whose checksums hold but whose values are NaN is refused by the commands that read its
// values, with one line naming the first such value, before anything is written.
TEST_F(VerifyCli, ReadersRefuseNonFiniteValues) {
  const DdgiResult& bad = result_;
  write_nan_sh("nan.bin", 40);
  std::ofstream(path("pts.csv")) << "0,0,0,0,1,0\n";
  const std::string first = "ddgi[0].sh probe " + std::to_string(40 / (3 * bad.desc.sh_coefficients()));
  const std::string scene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  for (const std::string& command : {"sample " + path("nan.bin") + " --points " + path("pts.csv") + " --source ddgi",
                                     "export " + path("nan.bin") + " --exr " + path("exr"),
                                     "preview " + scene + " --bake " + path("nan.bin") + " --out " + path("v.png")}) {
    const test::RunResult run = test::run_gibake(command);
    EXPECT_EQ(run.exit_code, 3) << command << "\n" << run.out;
    size_t errors = 0;  // preview's import progress comes first
    for (size_t at = run.out.find("gibake: error: "); at != std::string::npos;
         at = run.out.find("gibake: error: ", at + 1))
      ++errors;
    EXPECT_EQ(errors, 1u) << run.out;
    EXPECT_NE(run.out.find("nan.bin: " + first + ": 1 value(s) NaN or infinite"), std::string::npos) << run.out;
  }
  EXPECT_FALSE(std::filesystem::exists(path("exr")));
  EXPECT_FALSE(std::filesystem::exists(path("v.png")));
  // Invalid, it is compared with nothing, and the report says what did not run.
  const test::RunResult invalid =
      test::run_gibake_stdout("verify " + path("nan.bin") + " --against " + path("ref.bin") + " --scene " + scene);
  EXPECT_EQ(invalid.exit_code, 3) << invalid.out;
  for (const char* name : {"against", "staleness", "lit", "energy_bound"})
    EXPECT_NE(invalid.out.find(std::string("skip  ") + name + ": not run: the file failed the checks above"),
              std::string::npos)
        << name << "\n"
        << invalid.out;
  // As --against's reference it is an invalid input (exit 3), not a difference (exit 7).
  const test::RunResult against =
      test::run_gibake_stdout("verify " + path("ref.bin") + " --against " + path("nan.bin"));
  EXPECT_EQ(against.exit_code, 3) << against.out;
  EXPECT_NE(against.out.find("fail  against.integrity: " + path("nan.bin") + ": " + first), std::string::npos)
      << against.out;
  // The same file before the edit reads.
  EXPECT_EQ(test::run_gibake("sample " + path("ref.bin") + " --points " + path("pts.csv") + " --source ddgi").exit_code,
            0);
}

// A probe state the format does not define (a sampler would take it for a probe to sample) makes
// the file invalid, naming the probe and the state.
TEST_F(VerifyCli, UndefinedProbeStateIsInvalid) {
  DdgiResult bad = result_;
  ASSERT_EQ(bad.states.size(), size_t(bad.desc.probe_count()));
  bad.states[6] = static_cast<ProbeState>(200);
  ASSERT_TRUE(write(bad, "states.bin").is_ok());
  test::RunResult run = test::run_gibake_stdout("verify " + path("states.bin"));
  EXPECT_EQ(run.exit_code, 3) << run.out;
  EXPECT_NE(run.out.find("fail  ddgi[0].states: probe 6 has state 200, not 0 (active), 1 (inactive) or 2 (sky only)"),
            std::string::npos)
      << run.out;
  run = test::run_gibake_stdout("verify " + path("states.bin") + " --format json");
  EXPECT_EQ(run.exit_code, 3) << run.out;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  EXPECT_EQ(report["result"], "invalid");
  bool found = false;
  for (const auto& c : report["checks"])
    if (c["name"] == "ddgi[0].states") {
      found = true;
      EXPECT_EQ(c["status"], "fail");
      EXPECT_EQ(c["details"]["probe"], 6);
      EXPECT_EQ(c["details"]["state"], 200);
      EXPECT_EQ(c["details"]["count"], 1);
    }
  EXPECT_TRUE(found) << run.out;
  run = test::run_gibake_stdout("verify " + path("ref.bin"));  // its states are all defined
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("pass  ddgi[0].states"), std::string::npos) << run.out;
  // info counts the undefined state apart, not as an active probe.
  run = test::run_gibake_stdout("info " + path("states.bin"));
  EXPECT_NE(run.out.find(", 1 of a state the format does not define (verify refuses the file)"), std::string::npos)
      << run.out;
  run = test::run_gibake_stdout("info " + path("states.bin") + " --format json");
  const nlohmann::json info = nlohmann::json::parse(run.out);
  EXPECT_EQ(info["ddgi"][0]["undefined_state_probes"], 1) << run.out;
  run = test::run_gibake_stdout("info " + path("ref.bin") + " --format json");
  EXPECT_FALSE(nlohmann::json::parse(run.out)["ddgi"][0].contains("undefined_state_probes")) << run.out;
  // The commands that read the values refuse it too, as verify does.
  std::ofstream(path("pts.csv")) << "0,0,0,0,1,0\n";
  for (const std::string& command : {"sample " + path("states.bin") + " --points " + path("pts.csv") + " --source ddgi",
                                     "export " + path("states.bin") + " --vdb " + path("s.vdb")}) {
    run = test::run_gibake(command);
    EXPECT_EQ(run.exit_code, 3) << command << "\n" << run.out;
    EXPECT_NE(run.out.find("states.bin: ddgi[0].states: probe 6 has state 200"), std::string::npos) << run.out;
  }
  EXPECT_FALSE(std::filesystem::exists(path("s.vdb")));
}

// The metadata section holds one JSON object (FORMAT.md); text that is not one, under checksums
// that hold, makes the file invalid for verify and the readers, not a bake from before digests.
TEST_F(VerifyCli, MetadataThatIsNotJsonIsInvalid) {
  std::vector<uint8_t> bytes = test::read_bytes(path("ref.bin"));
  gibake_file_header h;
  std::memcpy(&h, bytes.data(), sizeof h);
  bool edited = false;
  for (size_t i = 0; i < h.section_count; ++i) {
    gibake_section_entry* e = test::table_entry(bytes, i);
    if (e->type != GIBAKE_SECTION_METADATA) continue;
    bytes[size_t(e->offset)] = 'x';  // the object's opening brace
    e->checksum = loader::xxh64(bytes.data() + e->offset, size_t(e->size), GIBAKE_HASH_SEED);
    edited = true;
  }
  ASSERT_TRUE(edited);
  test::reseal(bytes);
  test::write_bytes(path("meta.bin"), bytes);
  const test::RunResult run = test::run_gibake_stdout("verify " + path("meta.bin"));
  EXPECT_EQ(run.exit_code, 3) << run.out;
  EXPECT_NE(run.out.find("fail  metadata: the metadata section is not JSON"), std::string::npos) << run.out;
  std::ofstream(path("pts.csv")) << "0,0,0,0,1,0\n";
  const test::RunResult sample =
      test::run_gibake("sample " + path("meta.bin") + " --points " + path("pts.csv") + " --source ddgi");
  EXPECT_EQ(sample.exit_code, 3) << sample.out;
  EXPECT_NE(sample.out.find("meta.bin: metadata: the metadata section is not JSON"), std::string::npos) << sample.out;
  EXPECT_NE(test::run_gibake_stdout("verify " + path("ref.bin")).out.find("pass  metadata: one JSON object"),
            std::string::npos);
}

// sample's points: any non-zero float normal, however short or long, reads as its direction; a
// UTF-8 byte-order mark is no part of the first field; a device is refused (it never ends), a
// zero normal too.
TEST_F(VerifyCli, SamplePointsTakeAnyNonZeroNormal) {
  std::ofstream(path("unit.csv")) << "0,0,0,0,1,0\n";
  std::ofstream(path("odd.csv")) << "\xEF\xBB\xBF"
                                    "0,0,0,0,1e-30,0\n0,0,0,0,3e38,0\n";
  const std::string sample = "sample " + path("ref.bin") + " --source ddgi --points ";
  const test::RunResult unit = test::run_gibake_stdout(sample + path("unit.csv"));
  const test::RunResult odd = test::run_gibake_stdout(sample + path("odd.csv"));
  ASSERT_EQ(unit.exit_code, 0) << unit.out;
  ASSERT_EQ(odd.exit_code, 0) << odd.out;
  const auto light = [](const std::string& line) {  // the last three fields: the irradiance
    size_t at = line.size();
    for (int k = 0; k < 3; ++k) at = line.rfind(',', at - 1);
    return line.substr(at);
  };
  std::istringstream lines(odd.out);
  std::string first, second;
  std::getline(lines, first);
  std::getline(lines, second);
  const std::string expected = light(unit.out.substr(0, unit.out.find('\n')));
  EXPECT_EQ(light(first), expected) << odd.out;
  EXPECT_EQ(light(second), expected) << odd.out;
  std::ofstream(path("zero.csv")) << "0,0,0,0,0,0\n";
  const test::RunResult zero = test::run_gibake(sample + path("zero.csv"));
  EXPECT_EQ(zero.exit_code, 3) << zero.out;
  EXPECT_NE(zero.out.find("zero.csv: line 1: the normal has zero length"), std::string::npos) << zero.out;
  const test::RunResult device = test::run_gibake(sample + "/dev/zero");
  EXPECT_EQ(device.exit_code, 2) << device.out;
  EXPECT_EQ(device.out, "gibake: error: /dev/zero: --points: is not a regular file or a pipe\n");
}

// Probe p of two files stands at the same place only on the same grid: the same counts and values
// over a moved grid are a difference (exit 7), in either comparison.
TEST_F(VerifyCli, AMovedGridDiffers) {
  DdgiResult moved = result_;
  moved.desc.grid_min[0] += 0.25f;
  moved.desc.grid_max[0] += 0.25f;
  ASSERT_TRUE(write(moved, "moved.bin").is_ok());
  for (const char* mode : {"values", "statistical"}) {
    const test::RunResult run =
        test::run_gibake_stdout("verify " + path("moved.bin") + " --against " + path("ref.bin") + " --compare " + mode);
    EXPECT_EQ(run.exit_code, 7) << run.out;
    EXPECT_NE(run.out.find("fail  against.ddgi[0].structure: probe grid"), std::string::npos) << run.out;
  }
  EXPECT_EQ(test::run_gibake("verify " + path("ref.bin") + " --against " + path("ref.bin")).exit_code, 0);
}

// `--compare statistical` on what its noise model must get right. Each pair is a right one (it
// must pass) or a wrong one (it must fail), judged against what the probes report of their noise.
class VerifyStatisticalRules : public VerifyCli {
 protected:
  // `file` against `ref` (both written here): the exit code and the text report.
  test::RunResult compare(const DdgiResult& file, const DdgiResult& ref) {
    EXPECT_TRUE(write(file, "file.bin").is_ok());
    EXPECT_TRUE(write(ref, "against.bin").is_ok());
    return test::run_gibake_stdout("verify " + path("file.bin") + " --against " + path("against.bin") +
                                   " --compare statistical");
  }
  static void set_noise(DdgiResult& r, float relative_error) {
    for (DdgiProbeStats& s : r.stats) s.relative_error = relative_error;
  }
};

// A grid one probe deep on an axis has spacing 0 there: the offsets are judged against the
// spacing of the other axes (1.5 m), not a micrometre.
TEST_F(VerifyStatisticalRules, AFlatGridsOffsetsUseItsSpacing) {
  DdgiResult a = test::make_ddgi(4, 1, 4, 2, 5), b = a;
  for (size_t i = 0; i < b.offsets.size(); i += 3) b.offsets[i] += 0.01f;
  const test::RunResult run = compare(b, a);
  EXPECT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("pass  against.ddgi[0].offsets"), std::string::npos) << run.out;
}

// Light of another colour at the same luminance (blue up, red down so that every direction's
// luminance stays the same) is a wrong bake: the channels' means are judged too.
TEST_F(VerifyStatisticalRules, AnotherColourAtTheSameLuminanceFails) {
  DdgiResult a = test::make_ddgi(3, 2, 2, 2, 7), b = a;
  set_noise(a, 0.01f);
  set_noise(b, 0.01f);
  const int coefficients = a.desc.sh_coefficients();
  for (size_t p = 0; p < a.stats.size(); ++p)
    for (int c = 0; c < coefficients; ++c) {
      float* rgb = &b.sh[(p * size_t(coefficients) + size_t(c)) * 3];
      const float more_blue = 0.2f * rgb[2];
      rgb[2] += more_blue;
      rgb[0] -= 0.0722f / 0.2126f * more_blue;
    }
  const test::RunResult run = compare(b, a);
  EXPECT_EQ(run.exit_code, 7) << run.out;
  EXPECT_NE(run.out.find("fail  against.ddgi[0].irradiance_bias: mean irradiance (blue) +20"), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("pass  against.ddgi[0].sh_irradiance"), std::string::npos) << run.out;
}

// A depth texel whose rays both hit and escape has a wide spread (its moments' variance), and a
// right pair's means differ by much of it; a texel of no spread that moves as far is wrong.
TEST_F(VerifyStatisticalRules, DepthTexelsAreJudgedByTheirOwnSpread) {
  DdgiResult a = test::make_ddgi(3, 2, 2, 2, 9), b = a;
  for (size_t t = 0; t < a.depth_atlas.size(); t += 2) {
    a.depth_atlas[t] = 1.f, a.depth_atlas[t + 1] = 1.f + 100.f;  // sigma 10 m
    b.depth_atlas[t] = 5.f, b.depth_atlas[t + 1] = 25.f + 100.f;
  }
  test::RunResult run = compare(b, a);
  EXPECT_NE(run.out.find("pass  against.ddgi[0].depth_atlas"), std::string::npos) << run.out;
  for (size_t t = 0; t < a.depth_atlas.size(); t += 2) {
    a.depth_atlas[t + 1] = 1.f;  // no spread: every ray at 1 m, then at 5 m
    b.depth_atlas[t + 1] = 25.f;
  }
  run = compare(b, a);
  EXPECT_EQ(run.exit_code, 7) << run.out;
  EXPECT_NE(run.out.find("fail  against.ddgi[0].depth_atlas"), std::string::npos) << run.out;
}

// Probes so noisy that twice the light lies within the pair's allowance: the mean is not judged
// (skipped, and said why) rather than passed; with little noise twice the light fails.
TEST_F(VerifyStatisticalRules, APairTooNoisyToTellIsNotPassed) {
  DdgiResult a = test::make_ddgi(3, 2, 2, 2, 11), b = a;
  for (float& v : b.sh) v *= 2.f;
  for (float& v : b.irradiance_atlas) v *= 2.f;
  set_noise(a, 3.f);
  set_noise(b, 3.f);
  test::RunResult run = compare(b, a);
  EXPECT_NE(run.out.find("skip  against.ddgi[0].irradiance_bias: not judged: the pair's noise allows"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("not checked: against.ddgi[0].irradiance_bias"), std::string::npos) << run.out;
  set_noise(a, 0.02f);
  set_noise(b, 0.02f);
  run = compare(b, a);
  EXPECT_EQ(run.exit_code, 7) << run.out;
  EXPECT_NE(run.out.find("fail  against.ddgi[0].irradiance_bias"), std::string::npos) << run.out;
}

TEST_F(VerifyCli, MissingFileIsIoFailureAndStructureMismatchDiffers) {
  EXPECT_EQ(test::run_gibake("verify " + path("absent.bin")).exit_code, 2);
  EXPECT_EQ(test::run_gibake("verify " + dir_).exit_code, 2);  // a folder, not a file
  EXPECT_EQ(test::run_gibake("info " + dir_).exit_code, 2);
  // sample's points file: a folder would read as a file of no points.
  const test::RunResult points = test::run_gibake("sample " + path("ref.bin") + " --points " + dir_ + " --source ddgi");
  EXPECT_EQ(points.exit_code, 2) << points.out;
  EXPECT_EQ(points.out, "gibake: error: " + dir_ + ": --points: is a folder, not a file\n");
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

// A bake file from before content hashing (no metadata "inputs"; its header's hash that of the
// scene files' bytes, hash_inputs) verifies as it was made: fresh while the bytes are the same,
// stale when they are not, saying that which file cannot be told (a re-saved file reads as changed).
TEST(VerifyScene, ABakeFromBeforeContentHashingVerifiesByFileBytes) {
  const std::string sample_dir = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell";
  const std::string dir = test::scratch_dir("old_hash");
  for (const char* f : {"cornell.gltf", "cornell.bin"}) std::filesystem::copy_file(sample_dir + "/" + f, dir + "/" + f);
  const std::string scene = dir + "/cornell.gltf";
  Scene imported;
  ASSERT_TRUE(import_scene(scene, ImportOptions{}, Context{}, imported).is_ok());
  DdgiResult r = test::make_ddgi(2, 2, 2, 1, 51, false);
  for (float& v : r.sh) v *= 1e-3f;
  BakeOutputs outputs;
  outputs.ddgi = &r;
  ASSERT_TRUE(hash_inputs(imported.input_files, r.settings_json, outputs.input_hash).is_ok());
  ASSERT_TRUE(write_bake_file(dir + "/old.bin", outputs, BakeFileOptions{}, {}).is_ok());
  auto staleness = [&](int exit_code) {
    const test::RunResult run = test::run_gibake_stdout("verify " + dir + "/old.bin --scene " + scene + " --format json");
    EXPECT_EQ(run.exit_code, exit_code) << run.out;
    const nlohmann::json report = nlohmann::json::parse(run.out);
    for (const auto& c : report["checks"])
      if (c["name"] == "staleness") return c;
    return nlohmann::json();
  };
  nlohmann::json st = staleness(0);
  EXPECT_EQ(st["status"], "pass");
  EXPECT_EQ(st["details"]["hashed"], "file_bytes");
  EXPECT_NE(st["message"].get<std::string>().find("before content hashing"), std::string::npos) << st.dump();
  std::ofstream(scene) << nlohmann::json::parse(std::ifstream(sample_dir + "/cornell.gltf")).dump(1);
  st = staleness(7);
  EXPECT_EQ(st["status"], "fail");
  EXPECT_NE(st["message"].get<std::string>().find("which file and what changed cannot be told"), std::string::npos)
      << st.dump();
  std::filesystem::remove_all(dir);
}

// The summary of a real bake carries its reconstruction check and how its adaptive rays ended, and
// `verify --scene --max-reconstruction-error` passes that bake against its own scene but fails it
// against a copy of the scene whose lights are 4x brighter (the probes then hold a quarter of the
// indirect light: the worst tenth of patches far beyond a bound of 0.5), and needs --scene.
TEST(VerifyScene, ReconstructionBoundTellsARightBakeFromAWrongScene) {
  const std::string sample_dir = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell";
  const std::string scene = sample_dir + "/cornell.gltf";
  if (!std::filesystem::exists(scene)) GTEST_SKIP() << "no sample scene " << scene;
  const std::string dir = test::scratch_dir("recon");
  const std::string bake = dir + "/sample.gibake";
  const test::CliResult baked =
      test::run_gibake_cli(test::shell_quote(scene) +
                           " --ddgi --rays 128 --max-rays 1024 --ray-budget 384 --bounces 2 --check-patches 64"
                           " --progress json --out " +
                           test::shell_quote(bake));
  ASSERT_EQ(baked.exit_code, 0) << baked.err;
  nlohmann::json summary;
  std::istringstream lines(baked.err);
  for (std::string line; std::getline(lines, line);) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object() && j.value("event", "") == "summary") summary = j;
  }
  ASSERT_TRUE(summary.is_object()) << baked.err;
  const nlohmann::json& rec = summary["reconstruction"];
  ASSERT_TRUE(rec.is_object()) << summary.dump();
  EXPECT_EQ(rec["patches"].get<int>(), 64);
  EXPECT_GT(rec["counted"].get<int>(), 32);
  EXPECT_GT(rec["within_10pct"].get<double>(), 0.3);  // the sample reads ~0.9 at default settings
  EXPECT_LT(rec["p90_error"].get<double>(), 0.5);
  const nlohmann::json& adaptive = summary["adaptive"];
  ASSERT_TRUE(adaptive.is_object()) << summary.dump();
  EXPECT_FLOAT_EQ(adaptive["target_error"].get<float>(), 0.05f);
  const int probes = summary["probes"]["total"].get<int>(), inactive = summary["probes"]["inactive"].get<int>();
  EXPECT_EQ(adaptive["lit_probes"].get<int>(), probes - inactive);
  EXPECT_LE(adaptive["above_target"].get<int>(), adaptive["lit_probes"].get<int>());

  // The same scene with its point light and emitter 4x brighter (its buffer beside it).
  nlohmann::json gltf = nlohmann::json::parse(std::ifstream(scene));
  gltf["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] =
      4.0 * gltf["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"].get<double>();
  for (auto& m : gltf["materials"])
    if (m.contains("extensions") && m["extensions"].contains("KHR_materials_emissive_strength")) {
      auto& strength = m["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"];
      strength = 4.0 * strength.get<double>();
    }
  std::filesystem::copy_file(sample_dir + "/cornell.bin", dir + "/cornell.bin");
  std::ofstream(dir + "/bright.gltf") << gltf.dump();

  test::RunResult run =
      test::run_gibake_stdout("verify " + bake + " --scene " + scene + " --max-reconstruction-error 0.5 --format json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  bool checked = false;
  nlohmann::json report = nlohmann::json::parse(run.out);
  for (const auto& c : report["checks"])
    if (c["name"] == "reconstruction") {
      checked = true;
      EXPECT_EQ(c["status"], "pass");
      EXPECT_LT(c["details"]["p90_error"].get<double>(), 0.5);
      EXPECT_EQ(c["details"]["max_error"].get<double>(), 0.5);
    }
  EXPECT_TRUE(checked) << run.out;

  run = test::run_gibake_stdout("verify " + bake + " --scene " + dir +
                                "/bright.gltf --max-reconstruction-error 0.5"
                                " --format json");
  EXPECT_EQ(run.exit_code, 7) << run.out;
  checked = false;
  report = nlohmann::json::parse(run.out);
  for (const auto& c : report["checks"])
    if (c["name"] == "reconstruction") {
      checked = true;
      EXPECT_EQ(c["status"], "fail");
      // The indirect light is a quarter of the truth; shaded, the scene's own point light (4x in
      // both) lifts the ratio towards 1 where it lights a patch directly.
      EXPECT_NEAR(c["details"]["indirect_ratio_median"].get<double>(), 0.25, 0.05);
      EXPECT_GT(c["details"]["p90_error"].get<double>(), 0.5);
    }
  EXPECT_TRUE(checked) << run.out;

  // The bound needs the scene.
  EXPECT_EQ(test::run_gibake("verify " + bake + " --max-reconstruction-error 0.5").exit_code, 1);
  std::filesystem::remove_all(dir);
}

}  // namespace
