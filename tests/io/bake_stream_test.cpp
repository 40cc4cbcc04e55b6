// The bake file streamed during the bake (io/bakefile/bake_stream.h): rows told final in any order,
// some never, give the file the writer builds without a stream, byte for byte, its checksums
// verified by the loader; the predicted layout is the writer's; a wrong float16 guess, too little streamed, a layout
// other than predicted, or a stream never opened leave the writer to write the file from scratch, with the same bytes
// and no stray temporary.
#include "io/bakefile/bake_stream.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "tests/support/synthetic_ddgi.h"

namespace gibake {
namespace {

namespace fs = std::filesystem;

// 24x10x12 probes in three bands of Y planes (as a wide bake lays them out); `beyond`: an
// irradiance value past float16's range in the atlas's last rows.
DdgiResult make_result(bool beyond) {
  DdgiResult r = test::synthetic_ddgi({24, 10, 12}, 4);
  if (beyond) r.irradiance_atlas[r.irradiance_atlas.size() - 9] = 70000.f;
  return r;
}

// A result, the outputs naming it, options, and the file the writer builds from them in memory.
struct Written {
  DdgiResult r;
  BakeOutputs o;
  BakeFileOptions opt;
  std::vector<uint8_t> built;
  Written(bool beyond, uint64_t input_hash, FloatPrecision sh = FloatPrecision::Full) : r(make_result(beyond)) {
    o.ddgi = &r;
    o.input_hash = input_hash;
    opt.sh = sh;
    EXPECT_TRUE(build_bake_file(o, opt, built));
  }
};

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

// Files in `dir` other than `keep` (a stray temporary), less one when `keep` is missing.
int other_files(const fs::path& dir, const fs::path& keep) {
  int n = fs::exists(keep) ? 0 : -1;
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

// A test's folder, its build, and a stream for the build's file (not yet opened).
struct Streamed {
  StreamCase c;
  Written w;
  BakeFileStream stream;
  Streamed(bool beyond, uint64_t input_hash, FloatPrecision sh = FloatPrecision::Full)
      : w(beyond, input_hash, sh), stream(c.path, {}, w.opt) {}
};

// Opens `stream` for r's shape; whether it streams.
bool open_for(BakeFileStream& stream, const DdgiResult& r) {
  stream.open(shape_of(r), r.irradiance_atlas.data(), r.depth_atlas.data());
  return stream.active();
}

// Writes w's file through `stream`: the build's bytes, no temporary left.
void expect_build_written(const StreamCase& c, Written& w, BakeFileStream& stream) {
  w.opt.stream = &stream;
  ASSERT_TRUE(write_bake_file(c.path, w.o, w.opt, {}));
  EXPECT_TRUE(read_file(c.path) == w.built);
  EXPECT_EQ(other_files(c.dir, c.path), 0);
}

// The table predicted from the volume's shape alone is the writer's, section for section, for each
// storage choice the stream handles (predict_ddgi_table restates add_ddgi_sections' order).
TEST(BakeStream, PredictedTableIsTheWritersTable) {
  for (const FloatPrecision sh : {FloatPrecision::Full, FloatPrecision::Half})
    for (const FloatPrecision atlas : {FloatPrecision::Full, FloatPrecision::Half}) {
      Written w(false, 3);
      w.opt.sh = sh;
      w.opt.atlas = atlas;
      ASSERT_TRUE(build_bake_file(w.o, w.opt, w.built));
      std::vector<gibake_section_entry> predicted;
      uint64_t end = 0;
      ASSERT_TRUE(predict_ddgi_table(shape_of(w.r), w.opt, atlas == FloatPrecision::Half, predicted, end));
      gibake_file_header h;
      std::memcpy(&h, w.built.data(), sizeof h);
      ASSERT_EQ(h.section_count, predicted.size() + 1);  // and the metadata
      for (size_t i = 0; i < predicted.size(); ++i) {
        gibake_section_entry e;
        std::memcpy(&e, w.built.data() + h.section_table_offset + i * sizeof e, sizeof e);
        const gibake_section_entry& p = predicted[i];
        EXPECT_EQ(p.type, e.type) << i;
        EXPECT_EQ(p.format, e.format) << i;
        EXPECT_EQ(p.offset, e.offset) << i;
        EXPECT_EQ(p.size, e.size) << i;
        EXPECT_EQ(p.count, e.count) << i;
      }
      gibake_section_entry metadata;  // the section after them starts where the prediction ends
      std::memcpy(&metadata, w.built.data() + h.section_table_offset + predicted.size() * sizeof metadata,
                  sizeof metadata);
      EXPECT_EQ(end, metadata.offset);
    }
}

// Bands of tile rows told final from the last to the first, two of every three (as a trace's slabs
// finish, in no particular order); the rest are left to finish().
TEST(BakeStream, RowsFinalInAnyOrderWriteTheBuildsBytes) {
  Streamed s(false, 5);
  auto& [c, w, stream] = s;
  const DdgiResult& r = w.r;
  ASSERT_TRUE(open_for(stream, r));
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
  w.opt.stream = &stream;
  w.opt.timing = [&](const char* part, double) {
    adopted = adopted || std::string(part) == "streamed atlas rows left";
  };
  ASSERT_TRUE(write_bake_file(c.path, w.o, w.opt, {}));
  EXPECT_TRUE(adopted);
  EXPECT_TRUE(stream.adopted());
  EXPECT_EQ(stream.rows_written(BakeFileStream::kIrradiance), told[0]);
  EXPECT_EQ(stream.rows_written(BakeFileStream::kDepth), told[1]);
  const std::vector<uint8_t> file = read_file(c.path);
  EXPECT_TRUE(file == w.built) << "written " << file.size() << " bytes, built " << w.built.size();
  loader::BakeFile f;
  const loader::Error e = f.open(c.path, loader::LoadOptions{true});  // every checksum verified
  EXPECT_FALSE(e) << e.message;
  EXPECT_EQ(other_files(c.dir, c.path), 0);
}

// Under Auto the stream guesses float16; a value beyond it ends the stream and the writer stores
// the atlas in float32 from scratch.
TEST(BakeStream, WrongFloat16GuessFallsBackToTheWholeWrite) {
  Streamed s(true, 6);
  auto& [c, w, stream] = s;
  const DdgiResult& r = w.r;
  ASSERT_TRUE(open_for(stream, r));
  stream.rows_final(BakeFileStream::kIrradiance, 0, r.irradiance_height);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (stream.active() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(stream.active());  // the last rows hold 70000

  expect_build_written(c, w, stream);
}

// A stream that wrote less than half the atlases by the write (a bake whose probes all finished at
// its end) leaves the file to the writer.
TEST(BakeStream, LittleStreamedLeavesTheFileToTheWriter) {
  Streamed s(false, 8);
  auto& [c, w, stream] = s;
  const DdgiResult& r = w.r;
  ASSERT_TRUE(open_for(stream, r));
  stream.rows_final(BakeFileStream::kIrradiance, 0, r.irradiance_height / 3);
  ASSERT_TRUE(wait_written(stream, BakeFileStream::kIrradiance, r.irradiance_height / 3));
  expect_build_written(c, w, stream);
  EXPECT_FALSE(stream.adopted());
}

// A stream opened for another shape (the outputs grew a probe) is abandoned: the file is the build.
TEST(BakeStream, OtherLayoutIsAbandoned) {
  Streamed s(false, 7);
  auto& [c, w, stream] = s;
  const DdgiResult& r = w.r;
  DdgiFileShape other = shape_of(r);
  other.probes += 1;
  stream.open(other, r.irradiance_atlas.data(), r.depth_atlas.data());
  ASSERT_TRUE(stream.active());
  stream.rows_final(BakeFileStream::kDepth, 0, r.depth_height);
  expect_build_written(c, w, stream);
  EXPECT_FALSE(stream.adopted());
}

// With the SH's precision left to their values (Auto) the layout cannot be predicted: the stream
// opens nothing and the writer writes the build.
TEST(BakeStream, UnpredictableLayoutOpensNothing) {
  Streamed s(false, 9, FloatPrecision::Auto);
  auto& [c, w, stream] = s;
  const DdgiResult& r = w.r;
  EXPECT_FALSE(open_for(stream, r));
  EXPECT_EQ(other_files(c.dir, c.path), -1);  // not even a temporary
  expect_build_written(c, w, stream);
}

}  // namespace
}  // namespace gibake
