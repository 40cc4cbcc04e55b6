// Writer -> loader round trips (f32 bit-exact, f16 within 2^-11), and `gibake info` JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "io/bakefile/bake_file.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;

uint32_t bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

std::vector<uint8_t> build(const DdgiResult& r, bool f16, uint64_t hash = 0x1234) {
  BakeOutputs outputs;
  outputs.ddgi = &r;
  outputs.input_hash = hash;
  outputs.metadata_json = R"({"tool":"test","timings":{"total_s":1.5}})";
  BakeFileOptions options;
  options.sh = f16 ? gibake::FloatPrecision::Half : gibake::FloatPrecision::Full;
  options.atlas = f16 ? gibake::FloatPrecision::Half : gibake::FloatPrecision::Full;
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(build_bake_file(outputs, options, bytes).is_ok());
  return bytes;
}

void expect_near_f16(float got, float want) {
  EXPECT_LE(std::fabs(got - want), std::fabs(want) * std::exp2(-11.f) + std::exp2(-25.f)) << want;
}

TEST(BakeRoundTrip, Float32IsBitExact) {
  const DdgiResult r = test::make_ddgi(3, 2, 2, 2, 1);
  const std::vector<uint8_t> bytes = build(r, false);
  loader::BakeFile file;
  const loader::Error e = file.open_borrowed(bytes.data(), bytes.size());
  ASSERT_FALSE(e) << e.message;
  EXPECT_EQ(file.header().input_hash, 0x1234u);
  ASSERT_EQ(file.ddgi_volumes().size(), 1u);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  ASSERT_EQ(v.probe_count(), 12u);
  EXPECT_EQ(v.desc().sh_coefficients, 9u);
  for (uint32_t p = 0; p < 12; ++p) {
    for (uint32_t c = 0; c < 9; ++c)
      for (uint32_t k = 0; k < 3; ++k) ASSERT_EQ(bits(v.sh(p, c, k)), bits(r.sh[(p * 9 + c) * 3 + k]));
    for (uint32_t k = 0; k < 3; ++k) EXPECT_EQ(bits(v.offset(p)[k]), bits(r.offsets[p * 3 + k]));
    EXPECT_EQ(v.state(p), uint32_t(r.states[p]));
    EXPECT_EQ(v.stats(p).rays, r.stats[p].rays);
    EXPECT_EQ(bits(v.stats(p).relative_error), bits(r.stats[p].relative_error));
    EXPECT_EQ(bits(v.stats(p).nearest_front), bits(r.stats[p].nearest_front));
    EXPECT_EQ(bits(v.stats(p).backface_fraction), bits(r.stats[p].backface_fraction));
  }
  for (int y = 0; y < r.irradiance_height; ++y)
    for (int x = 0; x < r.irradiance_width; ++x)
      for (int k = 0; k < 4; ++k)
        ASSERT_EQ(bits(v.irradiance_texel(x, y)[k]), bits(r.irradiance_atlas[(y * r.irradiance_width + x) * 4 + k]));
  for (int y = 0; y < r.depth_height; ++y)
    for (int x = 0; x < r.depth_width; ++x)
      for (int k = 0; k < 2; ++k)
        ASSERT_EQ(bits(v.depth_texel(x, y)[k]), bits(r.depth_atlas[(y * r.depth_width + x) * 2 + k]));
  for (const gibake_section_entry& s : file.sections()) EXPECT_EQ(s.offset % 16, 0u);
  const nlohmann::json meta = nlohmann::json::parse(file.metadata_json());
  EXPECT_EQ(meta["tool"], "test");
  EXPECT_EQ(meta["settings"]["rays_per_probe"], 256);
  EXPECT_EQ(meta["format_version"], "1.2");
}

TEST(BakeRoundTrip, Float16WithinQuantisation) {
  DdgiResult r = test::make_ddgi(3, 2, 2, 1, 2);
  const std::vector<uint8_t> bytes = build(r, true);
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  EXPECT_EQ(v.sh_format(), uint32_t(GIBAKE_FORMAT_F16));
  for (uint32_t p = 0; p < 12; ++p)
    for (uint32_t c = 0; c < 4; ++c)
      for (uint32_t k = 0; k < 3; ++k) expect_near_f16(v.sh(p, c, k), r.sh[(p * 4 + c) * 3 + k]);
  for (int i = 0; i < r.irradiance_width * r.irradiance_height; i += 7)
    expect_near_f16(v.irradiance_texel(i % r.irradiance_width, i / r.irradiance_width)[0], r.irradiance_atlas[i * 4]);
  for (int i = 0; i < r.depth_width * r.depth_height; i += 5)
    expect_near_f16(v.depth_texel(i % r.depth_width, i / r.depth_width)[1], r.depth_atlas[i * 2 + 1]);
}

TEST(BakeRoundTrip, Float16ClampsAndWarns) {
  DdgiResult r = test::make_ddgi(1, 1, 1, 1, 3, false);
  r.sh[0] = 1e6f;
  BakeOutputs outputs;
  outputs.ddgi = &r;
  BakeFileOptions options;
  options.sh = gibake::FloatPrecision::Half;
  std::string warning;
  options.warn = [&](const std::string& m) { warning = m; };
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(build_bake_file(outputs, options, bytes).is_ok());
  EXPECT_NE(warning.find("65504"), std::string::npos);
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
  EXPECT_EQ(file.ddgi_volumes()[0].sh(0, 0, 0), 65504.f);
}

// Atlases of several conversion chunks (65,536 values each) give the same bytes at any thread
// count, and the clamped values are counted once each wherever their chunk ran.
TEST(BakeRoundTrip, Float16ChunksAreTheSameForAnyThreadCount) {
  DdgiResult r = test::make_ddgi(8, 8, 8, 2, 6);
  ASSERT_GT(r.depth_atlas.size(), size_t(4) * 65536);
  const size_t far[3] = {5, 70000 * 2 + 1, r.depth_atlas.size() - 2};  // chunks 0, 2 and the last
  for (size_t i : far) r.depth_atlas[i] = 1e6f;
  BakeOutputs outputs;
  outputs.ddgi = &r;
  std::vector<std::vector<uint8_t>> files;
  for (unsigned threads : {1u, 2u, 0u}) {
    BakeFileOptions options;
    options.atlas = gibake::FloatPrecision::Half;
    options.threads = threads;
    std::string warning;
    options.warn = [&](const std::string& m) { warning = m; };
    files.emplace_back();
    ASSERT_TRUE(build_bake_file(outputs, options, files.back()).is_ok());
    EXPECT_EQ(warning, "3 values above the float16 range were clamped to 65504") << threads;
  }
  EXPECT_EQ(files[0], files[1]);
  EXPECT_EQ(files[0], files[2]);
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(files[0].data(), files[0].size()));
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  for (size_t i : far) EXPECT_EQ(v.depth_texel(int((i / 2) % r.depth_width), int((i / 2) / r.depth_width))[i % 2], 65504.f);
}

TEST(BakeRoundTrip, WriterRejectsInconsistentResults) {
  DdgiResult r = test::make_ddgi(2, 2, 1, 2, 4);
  r.irradiance_width += 10;  // layout no longer matches the probe grid
  r.irradiance_atlas.resize(size_t(r.irradiance_width) * r.irradiance_height * 4, 0.f);
  BakeOutputs outputs;
  outputs.ddgi = &r;
  std::vector<uint8_t> bytes;
  const Status s = build_bake_file(outputs, BakeFileOptions{}, bytes);
  EXPECT_EQ(s.code(), ExitCode::InvalidInput);
  r = test::make_ddgi(2, 2, 1, 2, 4);
  r.sh.pop_back();
  EXPECT_EQ(build_bake_file(outputs, BakeFileOptions{}, bytes).code(), ExitCode::InvalidInput);
}

TEST(BakeInfoCli, ProbesJsonIsBitExact) {
  const std::string dir = test::scratch_dir("info");
  const DdgiResult r = test::make_ddgi(3, 2, 2, 2, 5);
  BakeOutputs outputs;
  outputs.ddgi = &r;
  BakeFileOptions options;
  options.atlas = gibake::FloatPrecision::Full;
  ASSERT_TRUE(write_bake_file(dir + "/probes.bin", outputs, options, {}).is_ok());
  const test::RunResult run = test::run_gibake_stdout("info " + dir + "/probes.bin --probes --format json");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const nlohmann::json info = nlohmann::json::parse(run.out);
  EXPECT_EQ(info["version"], "1.2");
  ASSERT_EQ(info["ddgi"].size(), 1u);
  const nlohmann::json& vol = info["ddgi"][0];
  EXPECT_EQ(vol["sh_order"], 2);
  EXPECT_EQ(vol["counts"], nlohmann::json::array({3, 2, 2}));
  ASSERT_EQ(vol["probes"].size(), 12u);
  for (uint32_t p = 0; p < 12; ++p) {
    const nlohmann::json& probe = vol["probes"][p];
    EXPECT_EQ(probe["index"], p);
    EXPECT_EQ(probe["state"], r.states[p] == ProbeState::Active ? "active" : "inactive");
    for (uint32_t c = 0; c < 9; ++c)
      for (uint32_t k = 0; k < 3; ++k)
        ASSERT_EQ(bits(probe["sh"][c][k].get<float>()), bits(r.sh[(p * 9 + c) * 3 + k]));
  }
  EXPECT_EQ(vol["probes"][4]["coord"], nlohmann::json::array({1, 1, 0}));
  const float x = -1.f + 1.5f * 1.f + r.offsets[4 * 3];
  EXPECT_EQ(bits(vol["probes"][4]["position"][0].get<float>()), bits(x));
  const test::RunResult text = test::run_gibake_stdout("info " + dir + "/probes.bin");
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("ddgi_sh"), std::string::npos);
  EXPECT_NE(text.out.find("3x2x2"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
