// Every output path is checked before any work starts. Two outputs naming
// one file (also through a hard link or a symlink), an output naming a file the command reads (the
// scene, its buffers, the sky HDR, the bake a preview reads), a folder given as an output and a
// missing output folder are refused with one line, exit 1 (argument clash) or 2 (I/O), nothing
// written and the earlier file's bytes unchanged.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "io/timer.h"
#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file

const std::string kSample = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
const std::string kSponza = std::string(GIBAKE_ASSETS_DIR) + "/sponza/Sponza.gltf";
const std::string kEarlier = "earlier bytes that must survive\n";

// A scratch folder holding a copy of the sample scene and one earlier output, o.gibake.
class OutputPaths : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = gibake::test::process_tmp() / (std::string("output_paths_") +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const fs::path sample = fs::path(kSample).parent_path();
    fs::copy_file(sample / "cornell.gltf", dir_ / "cornell.gltf");
    fs::copy_file(sample / "cornell.bin", dir_ / "cornell.bin");
    write(dir_ / "o.gibake", kEarlier);
    listing_ = listing();
  }
  void TearDown() override { fs::remove_all(dir_); }

  static void write(const fs::path& p, const std::string& text) {
    FILE* f = std::fopen(p.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fputs(text.c_str(), f);
    std::fclose(f);
  }
  std::string path(const std::string& name) const { return shell_quote((dir_ / name).string()); }
  std::string scene() const { return path("cornell.gltf"); }
  // Names and sizes of everything in the folder (temporaries included).
  std::string listing() const {
    std::string s;
    for (const auto& e : fs::directory_iterator(dir_))
      s += e.path().filename().string() + (e.is_regular_file() ? ":" + std::to_string(e.file_size()) : "") + "\n";
    return s;
  }
  // One error line naming `option`, the exit code, and nothing written or changed.
  void expect_refused(const std::string& args, int code, const std::string& option) {
    const CliResult r = run_gibake_cli(args);
    EXPECT_EQ(r.exit_code, code) << args << "\n" << r.err;
    const std::vector<std::string> lines = split_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("gibake: error: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find(option), std::string::npos) << lines[0];
    EXPECT_EQ(read_text_file((dir_ / "o.gibake").string()), kEarlier);
    EXPECT_EQ(read_text_file((dir_ / "cornell.bin").string()),
              read_text_file((fs::path(kSample).parent_path() / "cornell.bin").string()));
    EXPECT_EQ(listing(), listing_) << "something was written";
  }

  fs::path dir_;
  std::string listing_;
};

TEST_F(OutputPaths, TwoOutputsNamingOneFile) {
  expect_refused(scene() + " --ddgi --out " + path("o.gibake") + " --voxels " + path("o.gibake"), 1, "--voxels");
  expect_refused(scene() + " --ddgi --out " + path("x.gibake") + " --depfile " + path("x.gibake"), 1, "--depfile");
  expect_refused(scene() + " --ddgi --out " + path("x.gibake") + " --report " + path("./x.gibake"), 1, "--report");
}

TEST_F(OutputPaths, HardLinkAndSymlinkAreTheSameFile) {
  ASSERT_EQ(::link((dir_ / "o.gibake").c_str(), (dir_ / "hard.gibake").c_str()), 0);
  fs::create_symlink("o.gibake", dir_ / "soft.gibake");
  listing_ = listing();
  expect_refused(scene() + " --ddgi --out " + path("hard.gibake") + " --voxels " + path("o.gibake"), 1, "--voxels");
  expect_refused(scene() + " --ddgi --out " + path("soft.gibake") + " --report " + path("o.gibake"), 1, "--report");
}

TEST_F(OutputPaths, OutputNamingAnInput) {
  expect_refused(scene() + " --ddgi --out " + path("cornell.bin"), 1, "buffers[0]");  // the scene's buffer
  expect_refused(scene() + " --ddgi --out " + path("o.gibake") + " --report " + scene(), 1, "scene");
  expect_refused(scene() + " --ddgi --out " + path("o.gibake") + " --sky-hdr " + path("o.gibake"), 1, "--sky-hdr");
  expect_refused(scene() + " --voxels " + path("cornell.gltf"), 1, "--voxels");
  // preview: its image over the bake it reads, --diff over --out.
  expect_refused("preview " + scene() + " --bake " + path("o.gibake") + " --out " + path("o.png") + " --diff " +
                     path("o.png"),
                 1, "--diff");
  fs::rename(dir_ / "o.gibake", dir_ / "o.png");
  write(dir_ / "o.gibake", kEarlier);
  listing_ = listing();
  expect_refused("preview " + scene() + " --bake " + path("o.png") + " --out " + path("o.png"), 1, "--bake");
  expect_refused("export " + path("o.gibake") + " --vdb " + path("o.gibake"), 1, "--vdb");
}

TEST_F(OutputPaths, FolderAsOutputAndMissingFolder) {
  fs::create_directories(dir_ / "sub");
  listing_ = listing();
  expect_refused(scene() + " --ddgi --out " + path("sub"), 2, "is a folder");
  expect_refused(scene() + " --ddgi --out " + path("o.gibake") + " --voxels " + path("no/such/v.vdb"), 2,
                 "folder does not exist");
  expect_refused("preview " + scene() + " --mode albedo --out " + path("nowhere/view.png"), 2, "--out");
  expect_refused("export " + path("o.gibake") + " --exr " + path("no/such/dir"), 2, "--exr");
}

// Refused before the import: Sponza takes seconds to import and bake, the refusal well under one.
TEST(OutputPathsSponza, MissingFolderRefusedBeforeImport) {
  const gibake::Stopwatch timer;
  const CliResult r = run_gibake_cli(shell_quote(kSponza) + " --ddgi --sun 0.3,-1,0.2:100000 --out " +
                                     shell_quote("/nonexistent-gibake-folder/sponza.gibake"));
  const double seconds = timer.seconds();
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(split_lines(r.err).size(), 1u) << r.err;  // no import progress, no grid line
  EXPECT_NE(r.err.find("folder does not exist"), std::string::npos) << r.err;
  EXPECT_LT(seconds, 0.5);
}

}  // namespace
