// Atomic writes: old-or-new content, refusing inputs, missing folders, signals and kill -9.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "io/bakefile/bake_file.h"
#include "io/output/bake_atomic.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;

std::vector<std::string> temporaries(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) out.push_back(e.path().string());
  return out;
}

struct Child {
  pid_t pid = -1;
  FILE* out = nullptr;
};

Child spawn_helper(const std::string& mode, const std::string& path) {
  int fds[2];
  Child c;
  if (pipe(fds) != 0) return c;
  c.pid = fork();
  if (c.pid == 0) {
    dup2(fds[1], 1);
    close(fds[0]);
    close(fds[1]);
    execl(GIBAKE_ATOMIC_HELPER, GIBAKE_ATOMIC_HELPER, mode.c_str(), path.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  c.out = fdopen(fds[0], "r");
  return c;
}

std::string read_line(FILE* f) {
  char buf[4096] = {};
  return std::fgets(buf, sizeof buf, f) ? std::string(buf) : std::string();
}

int finish(Child& c, int sig) {
  kill(c.pid, sig);
  int status = 0;
  waitpid(c.pid, &status, 0);
  fclose(c.out);
  return WIFSIGNALED(status) ? WTERMSIG(status) : -1;
}

class AtomicWrite : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir("atomic");
    target_ = dir_ + "/probes.bin";
    old_ = test::make_ddgi(2, 2, 2, 1, 5);
    BakeOutputs outputs;
    outputs.ddgi = &old_;
    ASSERT_TRUE(write_bake_file(target_, outputs, BakeFileOptions{}, {}).is_ok());
    old_bytes_ = test::read_bytes(target_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string dir_, target_;
  DdgiResult old_;
  std::vector<uint8_t> old_bytes_;
};

TEST_F(AtomicWrite, ReplacesContentAndLeavesNoTemporary) {
  const DdgiResult fresh = test::make_ddgi(3, 2, 2, 2, 6);
  BakeOutputs outputs;
  outputs.ddgi = &fresh;
  std::vector<uint8_t> expected;
  ASSERT_TRUE(build_bake_file(outputs, BakeFileOptions{}, expected).is_ok());
  ASSERT_TRUE(write_bake_file(target_, outputs, BakeFileOptions{}, {}).is_ok());
  EXPECT_EQ(test::read_bytes(target_), expected);
  EXPECT_TRUE(temporaries(dir_).empty());
}

// commit(false), the BVH cache's: the same bytes renamed into place, no temporary left; only the
// fsyncs are skipped.
TEST_F(AtomicWrite, CommitWithoutFsyncStillReplacesAtomically) {
  const std::vector<uint8_t> bytes = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  AtomicFile file;
  ASSERT_TRUE(file.begin(target_));
  ASSERT_TRUE(file.write(bytes.data(), bytes.size()));
  EXPECT_EQ(test::read_bytes(target_), old_bytes_);  // the target is untouched until the commit
  ASSERT_TRUE(file.commit(/*durable=*/false));
  EXPECT_EQ(test::read_bytes(target_), bytes);
  EXPECT_TRUE(temporaries(dir_).empty());
}

TEST_F(AtomicWrite, RefusesToOverwriteAnInput) {
  const std::string link = dir_ + "/scene.gltf";
  ASSERT_EQ(::link(target_.c_str(), link.c_str()), 0);  // same inode, another name
  BakeOutputs outputs;
  outputs.ddgi = &old_;
  const Status s = write_bake_file(target_, outputs, BakeFileOptions{}, {link});
  EXPECT_EQ(s.code(), ExitCode::BadArguments);  // an argument mistake, not an invalid input file
  EXPECT_NE(s.message().find("refusing to overwrite an input"), std::string::npos) << s.message();
  EXPECT_EQ(test::read_bytes(target_), old_bytes_);
  EXPECT_TRUE(temporaries(dir_).empty());
}

// The writer's own guard, beneath every command's checks: a FIFO (or a device node, /dev/null as
// root) named as the output stays what it is, and no temporary is left.
TEST_F(AtomicWrite, AFifoIsNeverReplaced) {
  const std::string fifo = dir_ + "/fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  BakeOutputs outputs;
  outputs.ddgi = &old_;
  const Status s = write_bake_file(fifo, outputs, BakeFileOptions{}, {});
  EXPECT_EQ(s.code(), ExitCode::IoFailure);
  EXPECT_NE(s.message().find("not a file"), std::string::npos) << s.message();
  struct stat st;
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_TRUE(temporaries(dir_).empty());
}

TEST_F(AtomicWrite, MissingFolderIsIoFailure) {
  BakeOutputs outputs;
  outputs.ddgi = &old_;
  const Status s = write_bake_file(dir_ + "/nope/probes.bin", outputs, BakeFileOptions{}, {});
  EXPECT_EQ(s.code(), ExitCode::IoFailure);
  EXPECT_NE(s.message().find("folder does not exist"), std::string::npos) << s.message();
}

TEST_F(AtomicWrite, FailedWriteKeepsPreviousFile) {
  DdgiResult bad = test::make_ddgi(2, 2, 2, 1, 5);
  bad.sh.resize(3);  // rejected before any byte is written
  BakeOutputs outputs;
  outputs.ddgi = &bad;
  EXPECT_FALSE(write_bake_file(target_, outputs, BakeFileOptions{}, {}).is_ok());
  EXPECT_EQ(test::read_bytes(target_), old_bytes_);
  EXPECT_TRUE(temporaries(dir_).empty());
}

TEST_F(AtomicWrite, SigtermMidWriteRemovesTemporaryAndKeepsTarget) {
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    Child c = spawn_helper("hang", target_);
    ASSERT_GT(c.pid, 0);
    const std::string line = read_line(c.out);
    ASSERT_EQ(line.rfind("ready", 0), 0u) << line;
    EXPECT_EQ(temporaries(dir_).size(), 1u);
    EXPECT_EQ(finish(c, sig), sig);
    EXPECT_EQ(test::read_bytes(target_), old_bytes_);
    EXPECT_TRUE(temporaries(dir_).empty()) << "signal " << sig;
  }
}

// A run of several outputs (export) registers what it makes: a signal removes those files and
// then the folder it made, as a failure does; what it kept stays, and so does the folder then.
TEST_F(AtomicWrite, SignalRemovesProvisionalOutputsNotKeptOnes) {
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    const std::string made = dir_ + "/made";
    Child c = spawn_helper("made", made);
    ASSERT_GT(c.pid, 0);
    ASSERT_EQ(read_line(c.out).rfind("ready", 0), 0u);
    EXPECT_TRUE(std::filesystem::exists(made + "/a.bin"));
    EXPECT_EQ(finish(c, sig), sig);
    EXPECT_FALSE(std::filesystem::exists(made + "/a.bin")) << "signal " << sig;
    EXPECT_TRUE(std::filesystem::exists(made + "/kept.bin")) << "signal " << sig;
    EXPECT_TRUE(temporaries(made).empty()) << "signal " << sig;
    std::filesystem::remove(made + "/kept.bin");
    std::filesystem::remove(made);
    Child all = spawn_helper("made-all", made);  // nothing kept: the folder goes too
    ASSERT_GT(all.pid, 0);
    ASSERT_EQ(read_line(all.out).rfind("ready", 0), 0u);
    EXPECT_EQ(finish(all, sig), sig);
    EXPECT_FALSE(std::filesystem::exists(made)) << "signal " << sig;
  }
}

TEST_F(AtomicWrite, Kill9MidWriteKeepsPreviousTarget) {
  Child c = spawn_helper("hang", target_);
  ASSERT_GT(c.pid, 0);
  ASSERT_EQ(read_line(c.out).rfind("ready", 0), 0u);
  EXPECT_EQ(finish(c, SIGKILL), SIGKILL);
  EXPECT_EQ(test::read_bytes(target_), old_bytes_);
  // SIGKILL cannot be caught, so its temporary remains until the next write to the same target
  // removes it (the temporary's name carries the dead writer's pid).
  EXPECT_FALSE(temporaries(dir_).empty());
  const DdgiResult small = test::make_ddgi(2, 2, 2, 1, 5);
  BakeOutputs outputs;
  outputs.ddgi = &small;
  ASSERT_TRUE(write_bake_file(target_, outputs, BakeFileOptions{}, {}).is_ok());
  EXPECT_TRUE(temporaries(dir_).empty());
}

TEST_F(AtomicWrite, Kill9DuringRepeatedWritesLeavesAValidFile) {
  const DdgiResult big = test::make_ddgi(24, 16, 16, 2, 77);
  BakeOutputs outputs;
  outputs.ddgi = &big;
  BakeFileOptions options;
  options.atlas = gibake::FloatPrecision::Full;
  std::vector<uint8_t> fresh;
  ASSERT_TRUE(build_bake_file(outputs, options, fresh).is_ok());
  for (int round = 0; round < 5; ++round) {
    Child c = spawn_helper("loop", target_);
    ASSERT_GT(c.pid, 0);
    ASSERT_EQ(read_line(c.out).rfind("ready", 0), 0u);
    std::this_thread::sleep_for(std::chrono::milliseconds(7 + 13 * round));
    EXPECT_EQ(finish(c, SIGKILL), SIGKILL);
    const std::vector<uint8_t> now = test::read_bytes(target_);
    EXPECT_TRUE(now == fresh) << "target is neither complete old nor new content";
    loader::BakeFile file;
    EXPECT_FALSE(file.open_borrowed(now.data(), now.size()));
    for (const std::string& t : temporaries(dir_)) std::filesystem::remove(t);
  }
}

}  // namespace
