// Every output path is checked before any work starts. Two outputs naming
// one file (also through a hard link or a symlink), an output naming a file the command reads (the
// scene, its buffers, the sky HDR, the bake a preview reads), a folder given as an output and a
// missing output folder are refused with one line, exit 1 (argument clash) or 2 (I/O), nothing
// written and the earlier file's bytes unchanged.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <functional>
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

// A FIFO (or a device) named as an output would be replaced by the renamed temporary: refused, the
// node left as it is.
TEST_F(OutputPaths, FifoAsOutputIsRefused) {
  ASSERT_EQ(::mkfifo((dir_ / "pipe.gibake").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir_ / "pipe.html").c_str(), 0600), 0);
  listing_ = listing();
  expect_refused(scene() + " --ddgi --out " + path("pipe.gibake"), 2, "is a device, FIFO or socket, not a file");
  expect_refused(scene() + " --ddgi --out " + path("o.gibake") + " --report " + path("pipe.html"), 2, "--report");
  expect_refused(scene() + " --vxgi --out " + path("pipe.gibake"), 2, "is a device, FIFO or socket, not a file");
  expect_refused("merge " + path("o.gibake") + " --out " + path("pipe.gibake"), 2, "is a device, FIFO or socket");
  EXPECT_TRUE(fs::is_fifo(dir_ / "pipe.gibake"));
  EXPECT_TRUE(fs::is_fifo(dir_ / "pipe.html"));
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

// Light beyond a 32-bit float (an emission of 3e38 cd/m^2) would write NaN for every reader: the
// bake refuses to write it (exit 4, one line) and the earlier output keeps its bytes.
TEST_F(OutputPaths, LightBeyondAFloatIsRefusedNotWritten) {
  std::string gltf = read_text_file((dir_ / "cornell.gltf").string());
  const std::string strength = "\"emissiveStrength\": 10.0";
  ASSERT_NE(gltf.find(strength), std::string::npos);
  gltf.replace(gltf.find(strength), strength.size(), "\"emissiveStrength\": 3e38");
  write(dir_ / "cornell.gltf", gltf);
  listing_ = listing();
  const CliResult r = run_gibake_cli(scene() + " --ddgi --quality draft --out " + path("o.gibake"));
  EXPECT_EQ(r.exit_code, 4) << r.err;
  std::vector<std::string> errors;
  for (const std::string& line : split_lines(r.err))
    if (line.rfind("gibake: error: ", 0) == 0) errors.push_back(line);
  ASSERT_EQ(errors.size(), 1u) << r.err;
  EXPECT_NE(errors[0].find("o.gibake: bake result: "), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("NaN, infinite or beyond 1e36, first in ddgi[0].sh probe "), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("the light overflowed 32-bit floats"), std::string::npos) << errors[0];
  EXPECT_EQ(listing(), listing_);
  EXPECT_EQ(read_text_file((dir_ / "o.gibake").string()), kEarlier);
}

// Runs gibake with `args` under a file-size limit of `limit` bytes, its stderr into `err`. SIGXFSZ
// reaches gibake ignored (a write past the limit fails, EFBIG, as on a full disk) or, with
// `default_signal`, as a shell's `ulimit -f` leaves it (gibake must ignore it itself). The wait status.
int run_with_file_size_limit(const std::vector<std::string>& args, uintmax_t limit, std::string& err,
                             bool default_signal = false) {
  const std::string err_path = (process_tmp() / "limited.err").string();
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int fd = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDERR_FILENO);
    const int null = open("/dev/null", O_RDWR);
    dup2(null, STDIN_FILENO);
    dup2(null, STDOUT_FILENO);
    signal(SIGXFSZ, default_signal ? SIG_DFL : SIG_IGN);
    const struct rlimit rl { rlim_t(limit), rlim_t(limit) };
    setrlimit(RLIMIT_FSIZE, &rl);
    std::vector<char*> argv{const_cast<char*>(GIBAKE_EXE)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(GIBAKE_EXE, argv.data());
    _exit(127);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  err = read_text_file(err_path);
  fs::remove(err_path);
  return status;
}

// export: every file --exr and --vdb would write is checked before any is written. --vdb and the
// --exr folder naming one path, --vdb naming a file in the folder (by name or through a link), a
// --vdb name of another kind of file and an EXR name that is a folder are refused with one line,
// and nothing is written: no folder made, no EXR of the first volume left.
class ExportOutputs : public OutputPaths {
 protected:
  void SetUp() override {
    OutputPaths::SetUp();
    const CliResult r = run_gibake_cli(scene() + kTinyBake + " --out " + path("c.gibake"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    tree_ = tree();
  }
  static constexpr const char* kTinyBake =
      " --ddgi --probe-counts 2,2,2 --rays 32 --bounces 1 --target-error 0 --relocate off --reconstruction-check off";
  // Every path under the folder with its size: what a refused export must leave as it was.
  std::string tree() const {
    std::string s;
    for (const auto& e : fs::recursive_directory_iterator(dir_))
      s += fs::relative(e.path(), dir_).string() +
           (e.is_regular_file() ? ":" + std::to_string(e.file_size()) + ":" +
                                      std::to_string(std::hash<std::string>()(read_text_file(e.path().string())))
                                : "/") +
           "\n";
    return s;
  }
  // One error line, the exit code, a distinctive part of the line, and nothing written or changed.
  void expect_export_refused(const std::string& args, int code, const std::string& part) {
    const CliResult r = run_gibake_cli("export " + path("c.gibake") + " " + args);
    EXPECT_EQ(r.exit_code, code) << args << "\n" << r.err;
    const std::vector<std::string> lines = split_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(lines[0].rfind("gibake: error: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find(part), std::string::npos) << lines[0];
    EXPECT_EQ(r.out, "") << "paths printed as written";
    EXPECT_EQ(tree(), tree_) << args << ": something was written";
  }
  std::string tree_;
};

TEST_F(ExportOutputs, TwoOutputsNamingOneFileWriteNothing) {
  expect_export_refused("--exr " + path("same") + " --vdb " + path("same"), 1,
                        (dir_ / "same").string() + ": --vdb: names the folder --exr writes into");
  fs::create_directories(dir_ / "ex3");
  tree_ = tree();
  expect_export_refused("--exr " + path("ex3") + " --vdb " + path("ex3/irradiance.exr"), 1, "--vdb");
  expect_export_refused("--exr " + path("ex3/") + " --vdb " + path("./ex3"), 1, "names the folder --exr writes into");
  // A link to an EXR the export writes is that file.
  ASSERT_EQ(run_gibake_cli("export " + path("c.gibake") + " --exr " + path("ex3")).exit_code, 0);
  ASSERT_EQ(::link((dir_ / "ex3/sh.exr").c_str(), (dir_ / "ex3/sh.vdb").c_str()), 0);
  tree_ = tree();
  expect_export_refused("--exr " + path("ex3") + " --vdb " + path("ex3/sh.vdb"), 1,
                        "--vdb: names the same file as --exr (");
}

TEST_F(ExportOutputs, AnEXRNameThatIsAFolderWritesNothing) {
  fs::create_directories(dir_ / "ex2/sh.exr");
  tree_ = tree();
  expect_export_refused("--exr " + path("ex2"), 2, "ex2/sh.exr: --exr: is a folder, not a file");
  expect_export_refused("--exr " + path("ex2") + " --vdb " + path("v.vdb"), 2, "is a folder, not a file");
}

// --vdb writes an OpenVDB file: a name of another kind of file is refused (the scene it would have
// overwritten keeps its bytes); .vdb in any case and a name without an extension are taken.
TEST_F(ExportOutputs, VdbNamedAsAnotherKindIsRefused) {
  expect_export_refused("--vdb " + path("cornell.gltf"), 1,
                        "--vdb: names a glTF scene, but an OpenVDB file is written here: name it .vdb");
  for (const char* name : {"v.glb", "v.bin", "v.PNG", "v.exr", "other.gibake", "v.json", "v.html"})
    expect_export_refused("--vdb " + path(name), 1, "but an OpenVDB file is written here");
  for (const char* name : {"v.VDB", "grid"}) {
    const CliResult r = run_gibake_cli("export " + path("c.gibake") + " --vdb " + path(name));
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
    EXPECT_TRUE(fs::is_regular_file(dir_ / name)) << name;
  }
}

// A write that fails after the checks (here: a file size limit that the first image is under and
// a later one over) takes the files the export had written with it, and the --exr folder it made.
TEST_F(ExportOutputs, AFailedWriteLeavesNothingBehind) {
  const CliResult sizes = run_gibake_cli("export " + path("c.gibake") + " --exr " + path("sizes"));
  ASSERT_EQ(sizes.exit_code, 0) << sizes.err;
  const std::vector<std::string> written = split_lines(sizes.out);  // in the order written
  ASSERT_GE(written.size(), 2u) << sizes.out;
  const uintmax_t first = fs::file_size(written[0]);
  uintmax_t later = 0;
  for (size_t i = 1; i < written.size(); ++i) later = std::max(later, fs::file_size(written[i]));
  ASSERT_GT(later, first + 2048) << "the limit must fall between the first image and a later one";
  const uintmax_t limit = (first + later) / 2;
  std::string over;  // the first image over the limit: where the export fails
  for (size_t i = 1; i < written.size() && over.empty(); ++i)
    if (fs::file_size(written[i]) > limit) over = written[i];
  fs::remove_all(dir_ / "sizes");
  const std::string bake = (dir_ / "c.gibake").string(), out = (dir_ / "out").string(),
                    vdb = (dir_ / "out.vdb").string();
  std::string text;
  const int status = run_with_file_size_limit({"export", bake, "--exr", out, "--vdb", vdb}, limit, text);
  ASSERT_TRUE(WIFEXITED(status)) << text;
  EXPECT_EQ(WEXITSTATUS(status), 2) << text;
  EXPECT_EQ(split_lines(text).size(), 1u) << text;
  const std::string failed = fs::path(over).filename().string();
  EXPECT_NE(text.find("/out/" + failed + ": "), std::string::npos) << text;
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "the --exr folder and its images stayed";
  EXPECT_FALSE(fs::exists(dir_ / "out.vdb"));
  EXPECT_EQ(tree(), tree_);
}

// OpenVDB's own writer never checks its stream: a VDB cut short by the disk must fail, not land.
// Under a shell's `ulimit -f` the signal is not ignored either: the write past the limit must fail
// the same way, not kill gibake with its temporary file left in the folder.
TEST_F(ExportOutputs, AFailedVdbWriteLeavesNothingBehind) {
  const std::string bake = (dir_ / "c.gibake").string(), vdb = (dir_ / "whole.vdb").string();
  const CliResult whole = run_gibake_cli("export " + shell_quote(bake) + " --vdb " + shell_quote(vdb));
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const uintmax_t size = fs::file_size(vdb);
  fs::remove(vdb);
  for (const bool default_signal : {false, true}) {
    SCOPED_TRACE(default_signal ? "SIGXFSZ as the shell leaves it" : "SIGXFSZ ignored");
    std::string text;
    const int status = run_with_file_size_limit({"export", bake, "--vdb", vdb}, size / 2, text, default_signal);
    ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << ": "
                                   << text;
    EXPECT_EQ(WEXITSTATUS(status), 2) << text;
    EXPECT_EQ(split_lines(text).size(), 1u) << text;
    EXPECT_NE(text.find("whole.vdb: OpenVDB: the write failed"), std::string::npos) << text;
    EXPECT_EQ(tree(), tree_);
  }
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
