// The bake file streamed during the bake (io/bakefile/bake_stream.h): rows told final in any order,
// some never, give the file the writer builds without a stream, byte for byte, its checksums
// verified by the loader; a wrong float16 guess, a layout other than predicted, or a stream never
// opened leave the writer to write the file from scratch, with the same bytes and no stray temporary.
#include "io/bakefile/bake_stream.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "tests/support/ddgi_atlas_sizes.h"

namespace gibake {
namespace {

namespace fs = std::filesystem;

// 24x10x12 probes in three bands of Y planes (as a wide bake lays them out); `beyond`: irradiance
// values past float16's range in the atlas's last rows.
DdgiResult make_result(bool beyond) {
  DdgiResult r;
  r.desc.counts = {24, 10, 12};
  r.desc.sh_order = 2;
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = 0.f;
    r.desc.grid_max[a] = 5.f;
    r.desc.spacing[a] = 5.f / float(r.desc.counts[a] - 1);
  }
  r.desc.max_distance = 20.f;
  r.atlas_planes_per_row = 4;
  const size_t n = size_t(r.desc.probe_count());
  r.sh.resize(n * 27);
  for (size_t i = 0; i < r.sh.size(); ++i) r.sh[i] = std::sin(float(i)) * 300.f;
  r.offsets.assign(n * 3, 0.01f);
  r.states.assign(n, ProbeState::Active);
  r.stats.assign(n, DdgiProbeStats{64, 0.02f, 0.4f, 0.f});
  test::size_ddgi_atlases(r);
  for (size_t i = 0; i < r.irradiance_atlas.size(); ++i) r.irradiance_atlas[i] = float(i % 977) * 13.7f;
  if (beyond) r.irradiance_atlas[r.irradiance_atlas.size() - 9] = 70000.f;
  for (size_t i = 0; i < r.depth_atlas.size(); ++i) r.depth_atlas[i] = float(i % 501) * 0.01f;
  r.settings_json = R"({"rays":64})";
  return r;
}

DdgiFileShape shape_of(const DdgiResult& r) {
  DdgiFileShape s;
  s.probes = uint64_t(r.desc.probe_count());
  s.sh_values = r.sh.size();
  s.irradiance_width = r.irradiance_width;
  s.irradiance_height = r.irradiance_height;
  s.depth_width = r.depth_width;
  s.depth_height = r.depth_height;
  return s;
}

std::vector<uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Waits (5 s at most) until the stream wrote `rows` rows of `atlas`.
bool wait_written(BakeFileStream& stream, BakeFileStream::Atlas atlas, int rows) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (stream.rows_written(atlas) < rows) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// Files in `dir` other than `keep` (a stray temporary).
int other_files(const fs::path& dir, const fs::path& keep) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path() != keep;
  return n;
}

// A folder of the test's own (ctest runs the tests side by side).
struct StreamCase {
  fs::path dir = fs::temp_directory_path() /
                 (std::string("gibake_bake_stream_") + ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                  "_" + std::to_string(::getpid()));
  std::string path = (dir / "probes.gibake").string();
  StreamCase() {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~StreamCase() { fs::remove_all(dir); }
};

// Bands of tile rows told final from the last to the first, two of every three (as a trace's slabs
// finish, in no particular order); the rest are left to finish().
TEST(BakeStream, RowsFinalInAnyOrderWriteTheBuildsBytes) {
  StreamCase c;
  DdgiResult r = make_result(false);
  BakeOutputs o;
  o.ddgi = &r;
  o.input_hash = 5;
  BakeFileOptions opt;
  opt.atlas = FloatPrecision::Auto;
  std::vector<uint8_t> built;
  ASSERT_TRUE(build_bake_file(o, opt, built));

  BakeFileStream stream(c.path, {}, opt);
  stream.open(shape_of(r), r.irradiance_atlas.data(), r.depth_atlas.data());
  ASSERT_TRUE(stream.active());
  const int tiles[2] = {kIrradianceTexels + 2, kDepthTexels + 2};
  const int heights[2] = {r.irradiance_height, r.depth_height};
  int told[2] = {0, 0};
  for (int atlas = 0; atlas < 2; ++atlas)
    for (int band = heights[atlas] / tiles[atlas] - 1; band >= 0; --band) {
      if (band % 3 == 1) continue;
      stream.rows_final(BakeFileStream::Atlas(atlas), band * tiles[atlas], (band + 1) * tiles[atlas]);
      stream.rows_final(BakeFileStream::Atlas(atlas), band * tiles[atlas], band * tiles[atlas] + 1);  // again
      told[atlas] += tiles[atlas];
    }
  ASSERT_TRUE(wait_written(stream, BakeFileStream::kIrradiance, told[0]));
  ASSERT_TRUE(wait_written(stream, BakeFileStream::kDepth, told[1]));
  ASSERT_LT(told[0], heights[0]);  // finish() has rows left

  bool adopted = false;
  opt.stream = &stream;
  opt.timing = [&](const char* part, double) { adopted = adopted || std::string(part) == "streamed atlas rows left"; };
  ASSERT_TRUE(write_bake_file(c.path, o, opt, {}));
  EXPECT_TRUE(adopted);
  EXPECT_EQ(stream.rows_written(BakeFileStream::kIrradiance), told[0]);
  EXPECT_EQ(stream.rows_written(BakeFileStream::kDepth), told[1]);
  const std::vector<uint8_t> file = read_file(c.path);
  EXPECT_TRUE(file == built) << "written " << file.size() << " bytes, built " << built.size();
  loader::BakeFile f;
  const loader::Error e = f.open(c.path, loader::LoadOptions{true});  // every checksum verified
  EXPECT_FALSE(e) << e.message;
  EXPECT_EQ(other_files(c.dir, c.path), 0);
}

// Under Auto the stream guesses float16; a value beyond it ends the stream and the writer stores
// the atlas in float32 from scratch.
TEST(BakeStream, WrongFloat16GuessFallsBackToTheWholeWrite) {
  StreamCase c;
  DdgiResult r = make_result(true);
  BakeOutputs o;
  o.ddgi = &r;
  o.input_hash = 6;
  BakeFileOptions opt;
  std::vector<uint8_t> built;
  ASSERT_TRUE(build_bake_file(o, opt, built));

  BakeFileStream stream(c.path, {}, opt);
  stream.open(shape_of(r), r.irradiance_atlas.data(), r.depth_atlas.data());
  ASSERT_TRUE(stream.active());
  stream.rows_final(BakeFileStream::kIrradiance, 0, r.irradiance_height);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (stream.active() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(stream.active());  // the last rows hold 70000

  opt.stream = &stream;
  ASSERT_TRUE(write_bake_file(c.path, o, opt, {}));
  EXPECT_TRUE(read_file(c.path) == built);
  EXPECT_EQ(other_files(c.dir, c.path), 0);
}

// A stream that wrote less than half the atlases by the write (a bake whose probes all finished at
// its end) leaves the file to the writer.
TEST(BakeStream, LittleStreamedLeavesTheFileToTheWriter) {
  StreamCase c;
  DdgiResult r = make_result(false);
  BakeOutputs o;
  o.ddgi = &r;
  o.input_hash = 8;
  BakeFileOptions opt;
  std::vector<uint8_t> built;
  ASSERT_TRUE(build_bake_file(o, opt, built));
  BakeFileStream stream(c.path, {}, opt);
  stream.open(shape_of(r), r.irradiance_atlas.data(), r.depth_atlas.data());
  ASSERT_TRUE(stream.active());
  stream.rows_final(BakeFileStream::kIrradiance, 0, r.irradiance_height / 3);
  ASSERT_TRUE(wait_written(stream, BakeFileStream::kIrradiance, r.irradiance_height / 3));
  opt.stream = &stream;
  ASSERT_TRUE(write_bake_file(c.path, o, opt, {}));
  EXPECT_FALSE(stream.adopted());
  EXPECT_TRUE(read_file(c.path) == built);
  EXPECT_EQ(other_files(c.dir, c.path), 0);
}

// A stream opened for another shape (the outputs grew a band) is abandoned; one never opened (its
// layout unpredictable: SH under Auto) is ignored. The file is the build either way.
TEST(BakeStream, OtherLayoutOrNoneOpenedWritesTheBuild) {
  StreamCase c;
  DdgiResult r = make_result(false);
  BakeOutputs o;
  o.ddgi = &r;
  o.input_hash = 7;
  BakeFileOptions opt;
  std::vector<uint8_t> built;
  ASSERT_TRUE(build_bake_file(o, opt, built));
  {
    BakeFileStream stream(c.path, {}, opt);
    DdgiFileShape other = shape_of(r);
    other.probes += 1;
    stream.open(other, r.irradiance_atlas.data(), r.depth_atlas.data());
    ASSERT_TRUE(stream.active());
    stream.rows_final(BakeFileStream::kDepth, 0, r.depth_height);
    BakeFileOptions with = opt;
    with.stream = &stream;
    ASSERT_TRUE(write_bake_file(c.path, o, with, {}));
    EXPECT_TRUE(read_file(c.path) == built);
    EXPECT_EQ(other_files(c.dir, c.path), 0);
  }
  {
    BakeFileOptions auto_sh = opt;
    auto_sh.sh = FloatPrecision::Auto;
    std::vector<uint8_t> built_auto;
    ASSERT_TRUE(build_bake_file(o, auto_sh, built_auto));
    BakeFileStream stream(c.path, {}, auto_sh);
    stream.open(shape_of(r), r.irradiance_atlas.data(), r.depth_atlas.data());
    EXPECT_FALSE(stream.active());
    auto_sh.stream = &stream;
    ASSERT_TRUE(write_bake_file(c.path, o, auto_sh, {}));
    EXPECT_TRUE(read_file(c.path) == built_auto);
    EXPECT_EQ(other_files(c.dir, c.path), 0);
  }
}

}  // namespace
}  // namespace gibake
