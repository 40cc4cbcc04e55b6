// The bake writer's parallel, in-place path (io/bakefile/bake_file.cpp): the file written through
// the temporary-file sink is byte for byte the in-memory build, for one thread and for many, its
// checksums verify in the loader, and the float16 clamps are counted as the values put in say.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "tests/support/synthetic_ddgi.h"

namespace gibake {
namespace {

// 20x6x9 probes (or `counts`) with an atlas large enough to be split into many chunks; `beyond`
// irradiance values above 65504 (and one NaN) for the float16 clamp.
DdgiResult make_result(size_t beyond, std::array<int32_t, 3> counts = {20, 6, 9}) {
  DdgiResult r = test::synthetic_ddgi(counts);  // one band
  for (size_t k = 0; k < beyond; ++k) r.irradiance_atlas[(k * 7919) % r.irradiance_atlas.size()] = 70000.f + float(k);
  r.irradiance_atlas[5] = std::nanf("");
  return r;
}

TEST(BakeWrite, FileEqualsBuildForAnyThreadCountAndVerifies) {
  const DdgiResult r = make_result(1000);
  BakeOutputs o;
  o.ddgi = &r;
  o.input_hash = 7;
  BakeFileOptions opt;
  opt.atlas = FloatPrecision::Half;  // clamps the 1000 values above the range
  size_t warned = 0;
  opt.warn = [&](const std::string& w) { warned = std::stoul(w); };
  opt.threads = 1;
  std::vector<uint8_t> one;
  ASSERT_TRUE(build_bake_file(o, opt, one));
  EXPECT_EQ(warned, 1000u);
  opt.threads = 0;
  std::vector<uint8_t> many;
  ASSERT_TRUE(build_bake_file(o, opt, many));
  EXPECT_TRUE(one == many);
  const std::string path = (std::filesystem::temp_directory_path() / "gibake_bake_write_test.gibake").string();
  warned = 0;
  ASSERT_TRUE(write_bake_file(path, o, opt, {}));
  EXPECT_EQ(warned, 1000u);
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(file == one) << "written " << file.size() << " bytes, built " << one.size();
  loader::BakeFile f;
  const loader::Error e = f.open(path, loader::LoadOptions{true});
  EXPECT_FALSE(e) << e.message;
  std::filesystem::remove(path);
}

// A 20 MB atlas goes to the temporary file in 4 MiB pieces side by side (beside its checksum): the
// file is still the build, byte for byte.
TEST(BakeWrite, LargeSectionsWrittenInPiecesEqualTheBuild) {
  const DdgiResult r = make_result(0, {64, 12, 16});
  BakeOutputs o;
  o.ddgi = &r;
  o.input_hash = 11;
  BakeFileOptions opt;
  opt.atlas = FloatPrecision::Full;
  std::vector<uint8_t> built;
  ASSERT_TRUE(build_bake_file(o, opt, built));
  ASSERT_GT(r.irradiance_atlas.size() * 4, size_t(16) << 20);  // five pieces at least
  const std::string path = (std::filesystem::temp_directory_path() / "gibake_bake_write_pieces.gibake").string();
  ASSERT_TRUE(write_bake_file(path, o, opt, {}));
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(file == built) << "written " << file.size() << " bytes, built " << built.size();
  loader::BakeFile f;
  const loader::Error e = f.open(path, loader::LoadOptions{true});  // every checksum verified
  EXPECT_FALSE(e) << e.message;
  std::filesystem::remove(path);
}

// The files' hash computed ahead and finished later (the bake hashes the scene beside its stages)
// is hash_inputs' value, finished once or twice; the settings and each file's bytes change it.
TEST(BakeWrite, InputHashInTwoStepsIsHashInputs) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string a = (dir / "gibake_input_hash_a.bin").string(), b = (dir / "gibake_input_hash_b.bin").string();
  std::ofstream(a, std::ios::binary) << std::string(3 << 20, 'x');  // more than one read buffer
  std::ofstream(b, std::ios::binary) << "scene";
  uint64_t whole = 0, first = 0, second = 0, other_settings = 0, other_file = 0;
  ASSERT_TRUE(hash_inputs({a, b}, R"({"rays":64})", whole));
  InputHash ahead;
  ASSERT_TRUE(ahead.add_files({a, b}));
  ASSERT_TRUE(ahead.finish(R"({ "rays": 64 })", first));  // canonicalised like hash_inputs
  ASSERT_TRUE(ahead.finish(R"({"rays":64})", second));
  EXPECT_EQ(first, whole);
  EXPECT_EQ(second, whole);
  ASSERT_TRUE(ahead.finish(R"({"rays":65})", other_settings));
  EXPECT_NE(other_settings, whole);
  std::ofstream(b, std::ios::binary) << "scenf";
  InputHash changed;
  ASSERT_TRUE(changed.add_files({a, b}));
  ASSERT_TRUE(changed.finish(R"({"rays":64})", other_file));
  EXPECT_NE(other_file, whole);
  InputHash missing;
  EXPECT_EQ(missing.add_files({(dir / "gibake_input_hash_missing.bin").string()}).code(), ExitCode::IoFailure);
  std::filesystem::remove(a);
  std::filesystem::remove(b);
}

// The reader beside the commit sees exactly the committed bytes; its error comes back, and the file
// is committed all the same (it is complete and valid: only the reader failed).
TEST(BakeWrite, ReaderBesideTheCommitSeesTheFileBytes) {
  const DdgiResult r = make_result(0);
  BakeOutputs o;
  o.ddgi = &r;
  o.input_hash = 9;
  std::vector<uint8_t> built;
  ASSERT_TRUE(build_bake_file(o, BakeFileOptions{}, built));
  const std::string path = (std::filesystem::temp_directory_path() / "gibake_bake_write_reader.gibake").string();
  std::vector<uint8_t> seen;
  const BytesReader copy = [&](const uint8_t* data, size_t size) {
    seen.assign(data, data + size);
    return Status::ok();
  };
  ASSERT_TRUE(write_bake_file(path, o, BakeFileOptions{}, {}, copy));
  EXPECT_TRUE(seen == built) << "seen " << seen.size() << " bytes, built " << built.size();
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_TRUE(file == built);
  const BytesReader fails = [](const uint8_t*, size_t) { return Status::invalid("", "reader", "no"); };
  std::filesystem::remove(path);
  const Status s = write_bake_file(path, o, BakeFileOptions{}, {}, fails);
  EXPECT_EQ(s.code(), ExitCode::InvalidInput);
  EXPECT_EQ(s.what(), "no");
  EXPECT_TRUE(std::filesystem::exists(path));
  std::filesystem::remove(path);
}

TEST(BakeWrite, BadOutputsWriteNothing) {
  DdgiResult r = make_result(0);
  r.sh.pop_back();
  BakeOutputs o;
  o.ddgi = &r;
  const std::string path = (std::filesystem::temp_directory_path() / "gibake_bake_write_bad.gibake").string();
  std::filesystem::remove(path);
  const Status s = write_bake_file(path, o, BakeFileOptions{}, {});
  EXPECT_EQ(s.code(), ExitCode::InvalidInput);
  EXPECT_EQ(s.file(), path);
  EXPECT_FALSE(std::filesystem::exists(path));
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path()))
    EXPECT_EQ(entry.path().filename().string().find(".gibake_bake_write_bad"), std::string::npos);
}

}  // namespace
}  // namespace gibake
