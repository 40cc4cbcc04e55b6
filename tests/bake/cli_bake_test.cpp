// The bake command end to end: exit codes and a written file.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace {
int run(const std::string& args) {
  const std::string cmd = std::string(GIBAKE_EXE) + " " + args + " 2>/dev/null";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
const std::string kSaw = std::string(GIBAKE_ASSETS_DIR) + "/reciprocating-saw/ReciprocatingSaw.gltf";
}  // namespace

TEST(BakeCli, WritesProbesAndReportsBadArguments) {
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "gibake_bake_cli_test.bin";
  std::filesystem::remove(out);
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() +
                " --probe-counts 3,3,3 --rays 64 --bounces 1 --sun 0,-1,0:1000 --sky 0.1,0.1,0.1 --progress json"),
            0);
  EXPECT_TRUE(std::filesystem::exists(out));
  EXPECT_GT(std::filesystem::file_size(out), 1000u);
  std::filesystem::remove(out);
  EXPECT_EQ(run(kSaw + " --out " + out.string()), 1);                          // no --ddgi
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --sun 1,2"), 1);    // malformed --sun
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --sh-order 3"), 1);  // unsupported order
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --probe-spacing 0.0001"), 1);  // probe cap
  EXPECT_EQ(run(kSaw + " --ddgi --out " + out.string() + " --sky-hdr /nonexistent/sky.exr"), 2);
  EXPECT_FALSE(std::filesystem::exists(out));
}
