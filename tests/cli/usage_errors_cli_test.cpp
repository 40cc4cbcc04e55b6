// Mistakes at the terminal get one line that names the mistake and, where there is one, the fix:
// a mistyped option or command gets the nearest name, a bad value is repeated, a bake file given
// as the scene is named as one, a bake file named .png is refused, and Ctrl-C says what happened.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "tests/support/cli_run.h"
#include "tests/support/cli_errors.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file

const std::string kSample = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";

std::string scratch(const std::string& name) { return (gibake::test::process_tmp() / ("usage_" + name)).string(); }

std::string one_error(const std::string& args) { return usage_error_line(args); }

const std::string kBake = shell_quote(kSample) + " --ddgi --out " + shell_quote(scratch("never.gibake"));

TEST(UsageErrors, MistypedOptionGetsTheNearestName) {
  EXPECT_EQ(one_error(kBake + " --ray 64"), "gibake: error: --ray: unknown option of 'gibake bake'; did you mean --rays?");
  EXPECT_EQ(one_error(kBake + " --bounce=3"),
            "gibake: error: --bounce: unknown option of 'gibake bake'; did you mean --bounces?");
  EXPECT_EQ(one_error("info x.gibake --prob"), "gibake: error: --prob: unknown option of 'gibake info'; did you mean --probes?");
  EXPECT_EQ(one_error(kBake + " --zzzzzzzz"),
            "gibake: error: --zzzzzzzz: unknown option of 'gibake bake'; 'gibake bake --help' lists them");
  EXPECT_EQ(one_error(kBake + " -x"), "gibake: error: -x: unknown option of 'gibake bake'; 'gibake bake --help' lists them");
  EXPECT_EQ(one_error(kBake + " second.gltf"), "gibake: error: second.gltf: unexpected argument of 'gibake bake'");
  EXPECT_FALSE(fs::exists(scratch("never.gibake")));
}

TEST(UsageErrors, MistypedCommandIsNotReadAsAScene) {
  EXPECT_EQ(one_error("veriy x.gibake"), "gibake: error: veriy: unknown command; did you mean 'verify'?");
  EXPECT_EQ(one_error("inspekt scene.gltf"), "gibake: error: inspekt: unknown command; did you mean 'inspect'?");
  EXPECT_EQ(one_error("frobnicate"),
            "gibake: error: frobnicate: not a command (bake, inspect, info, verify, export, preview, merge, sample) "
            "nor a scene file");
  // A path stays a scene: the import says it is missing (exit 2).
  const CliResult missing = run_gibake_cli("no/such/scene.gltf --ddgi --out " + shell_quote(scratch("x.gibake")));
  EXPECT_EQ(missing.exit_code, 2) << missing.err;
}

TEST(UsageErrors, BadValuesAreRepeated) {
  EXPECT_EQ(one_error(kBake + " --gather paht"), "gibake: error: --gather: expected 'path' or 'probes', got 'paht'");
  EXPECT_EQ(one_error(kBake + " --progress line"),
            "gibake: error: --progress: expected auto, bar, lines or json, got 'line'");
  EXPECT_EQ(one_error(kBake + " --probe-counts 4,4"),
            "gibake: error: --probe-counts: expected three whole numbers X,Y,Z from 1 to 1000000, got '4,4'");
  EXPECT_EQ(one_error(kBake + " --light-sampling one"),
            "gibake: error: --light-sampling: expected 'all' or 'random', got 'one'");
  EXPECT_EQ(one_error(kBake + " --sh-format f8"), "gibake: error: --sh-format: expected f32, f16 or auto, got 'f8'");
  EXPECT_EQ(one_error(kBake + " --fit-gather probe"),
            "gibake: error: --fit-gather: expected 'both', 'paths' or 'probes', got 'probe'");
  EXPECT_EQ(one_error(kBake + " --fit-solves 3"),
            "gibake: error: --fit-solves: expected a whole number in 1..2, got '3'");
  EXPECT_EQ(one_error("merge a.gibake --out " + shell_quote(scratch("m.gibake")) + " --progress bars"),
            "gibake: error: --progress: expected auto, bar, lines or json, got 'bars'");
  EXPECT_FALSE(fs::exists(scratch("never.gibake")));
}

// Range errors name the option and repeat the value, before any work: a preview's field of view
// of 0 (which would silently become the glTF camera's), a negative normal bias (which would
// silently become the loader's), a negative or NaN reconstruction bound of verify (which would
// skip the check).
TEST(UsageErrors, OutOfRangeValuesAreRefused) {
  const std::string preview =
      "preview " + shell_quote(kSample) + " --mode albedo --size 8x8 --out " + shell_quote(scratch("p.png"));
  EXPECT_EQ(one_error(preview + " --fov 0"),
            "gibake: error: --fov: field of view must be in (0, 179) degrees, got '0'");
  EXPECT_EQ(one_error(preview + " --fov 179"),
            "gibake: error: --fov: field of view must be in (0, 179) degrees, got '179'");
  EXPECT_EQ(one_error(preview + " --normal-bias -1"),
            "gibake: error: --normal-bias: expected a number, 0 or more, got '-1'");
  EXPECT_FALSE(fs::exists(scratch("p.png")));
  const std::string verify = "verify x.gibake --scene " + shell_quote(kSample);
  EXPECT_EQ(one_error(verify + " --max-reconstruction-error -1"),
            "gibake: error: --max-reconstruction-error: expected a number, 0 or more, got '-1'");
  // NaN is refused with every number option's wording; no longer a check silently skipped.
  const std::string nan = one_error(verify + " --max-reconstruction-error nan");
  EXPECT_EQ(nan.rfind("gibake: error: --max-reconstruction-error: expected ", 0), 0u) << nan;
  EXPECT_NE(nan.find("got 'nan'"), std::string::npos) << nan;
}

TEST(UsageErrors, BakeFileGivenAsTheSceneIsNamed) {
  const std::string bake = scratch("real.gibake");
  ASSERT_EQ(run_gibake_cli(shell_quote(kSample) + " --ddgi --rays 16 --bounces 0 --reconstruction-check off --out " +
                           shell_quote(bake))
                .exit_code,
            0);
  for (const std::string& args : {shell_quote(bake) + " --ddgi --out " + shell_quote(scratch("again.gibake")),
                                  shell_quote(bake) + " --ddgi", "inspect " + shell_quote(bake),
                                  "preview " + shell_quote(bake) + " --mode albedo --out " + shell_quote(scratch("v.png"))}) {
    const CliResult r = run_gibake_cli(args);
    EXPECT_EQ(r.exit_code, 3) << args;
    EXPECT_EQ(r.err, "gibake: error: " + bake + ": a gibake bake file, not a scene: give the .gltf or .glb to read\n");
  }
  EXPECT_FALSE(fs::exists(scratch("again.gibake")));
  fs::remove(bake);
}

// A bake file named as an image, a scene or a volume file is refused before any work (exit 1);
// .gibake, .bin and names without an extension are taken.
TEST(UsageErrors, BakeFileNamedAsAnotherKindIsRefused) {
  const std::string png = scratch("y.png");
  EXPECT_EQ(one_error(shell_quote(kSample) + " --ddgi --out " + shell_quote(png)),
            "gibake: error: " + png + ": --out: names a PNG image, but a bake file is written here: name it .gibake");
  EXPECT_FALSE(fs::exists(png));
  EXPECT_NE(one_error(shell_quote(kSample) + " --lpv --out " + shell_quote(scratch("s.GLTF"))).find("names a glTF scene"),
            std::string::npos);
  // The bake's other outputs likewise: each named as another kind of file is refused.
  EXPECT_EQ(
      one_error(shell_quote(kSample) + " --voxels " + shell_quote(png)),
      "gibake: error: " + png + ": --voxels: names a PNG image, but an OpenVDB file is written here: name it .vdb");
  EXPECT_NE(one_error(shell_quote(kSample) + " --ddgi --out " + shell_quote(scratch("r.gibake")) + " --report " +
                      shell_quote(png))
                .find("--report: names a PNG image, but a web page is written here: name it .html"),
            std::string::npos);
  EXPECT_NE(one_error(shell_quote(kSample) + " --ddgi --out " + shell_quote(scratch("r.gibake")) + " --depfile " +
                      shell_quote(scratch("d.gltf")))
                .find("--depfile: names a glTF scene, but a Makefile depfile is written here: name it .d"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(png));
  const std::string bin = scratch("probes.bin");
  const CliResult r = run_gibake_cli(shell_quote(kSample) + " --ddgi --rays 16 --bounces 0 --reconstruction-check off "
                                     "--out " + shell_quote(bin));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(bin));
  fs::remove(bin);
}

// Ctrl-C during a bake: the process ends by SIGINT (the shell's exit status 130) after one line
// saying so, and no bake file is left.
TEST(UsageErrors, InterruptSaysSo) {
  const std::string out = scratch("interrupted.gibake"), err = scratch("interrupted.err");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int fd = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDERR_FILENO);
    const int null = open("/dev/null", O_RDWR);
    dup2(null, STDIN_FILENO);
    dup2(null, STDOUT_FILENO);
    signal(SIGINT, SIG_DFL);
    execl(GIBAKE_EXE, GIBAKE_EXE, kSample.c_str(), "--ddgi", "--rays", "65536", "--target-error", "0", "--bounces",
          "16", "--progress", "lines", "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Once the bake has begun (its first progress line), interrupt it.
  for (int i = 0; i < 600 && read_text_file(err).find("gibake:") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const std::string text = read_text_file(err);
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit " << WEXITSTATUS(status) << "\n" << text;
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  const std::vector<std::string> lines = split_lines(text);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back(), "gibake: interrupted (SIGINT); no output was left half-written") << text;
  for (const auto& entry : fs::directory_iterator(gibake::test::process_tmp()))  // nor its temporary
    EXPECT_EQ(entry.path().filename().string().find("interrupted.gibake"), std::string::npos) << entry.path();
  fs::remove(err);
}

}  // namespace
