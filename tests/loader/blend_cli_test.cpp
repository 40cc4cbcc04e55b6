// `gibake info` and `gibake sample --source ddgi` on a file of several DDGI volumes: every volume
// listed, every point the loader's blend (BakeFile::sample_ddgi) to the printed digit, empty outside.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "gibake/loader.hpp"
#include "multi_volume.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;

TEST(BlendCli, InfoListsEveryVolumeAndSampleBlends) {
  const std::string dir = test::scratch_dir("blend_cli");
  DdgiResult coarse = test::make_ddgi(4, 4, 4, 2, 601), fine = test::make_ddgi(4, 4, 4, 2, 602);
  for (int a = 0; a < 3; ++a) {  // coarse: probes 0..6 m (spacing 2); fine: 1..2.5 m (spacing 0.5)
    coarse.desc.grid_min[a] = 0.f, coarse.desc.spacing[a] = 2.f, coarse.desc.grid_max[a] = 6.f;
    fine.desc.grid_min[a] = 1.f, fine.desc.spacing[a] = 0.5f, fine.desc.grid_max[a] = 2.5f;
  }
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(test::multi_volume_bytes({&coarse, &fine}, BakeFileOptions{}, bytes, "{}").is_ok());
  const std::string file = dir + "/two.gibake", points = dir + "/points.csv";
  test::write_bytes(file, bytes);
  loader::BakeFile loaded;
  ASSERT_FALSE(loaded.open(file));

  const test::RunResult info = test::run_gibake_stdout("info " + file);
  ASSERT_EQ(info.exit_code, 0) << info.out;
  EXPECT_NE(info.out.find("ddgi volume 0: 4x4x4 probes"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("ddgi volume 1: 4x4x4 probes"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("spacing [0.5,0.5,0.5]"), std::string::npos) << info.out;

  // Deep in the fine volume, in its fade band, in the coarse one only, outside both.
  const std::vector<loader::Vec3> at{{1.7f, 1.8f, 1.9f}, {0.8f, 1.5f, 2.f}, {5.f, 4.f, 3.f}, {9.f, 1.f, 1.f}};
  std::ostringstream csv;
  for (const loader::Vec3& p : at) csv << p[0] << "," << p[1] << "," << p[2] << ",0,1,0\n";
  const std::string text = csv.str();
  test::write_bytes(points, std::vector<uint8_t>(text.begin(), text.end()));
  const test::RunResult run = test::run_gibake_stdout("sample " + file + " --points " + points + " --source ddgi");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::istringstream lines(run.out);
  std::string line;
  for (const loader::Vec3& p : at) {
    ASSERT_TRUE(std::getline(lines, line));
    loader::Rgb e;
    const bool inside = loaded.sample_ddgi(p, {0.f, 1.f, 0.f}, e);
    char expected[160];
    if (inside)
      std::snprintf(expected, sizeof expected, ",%.9g,%.9g,%.9g", double(e[0]), double(e[1]), double(e[2]));
    else
      std::snprintf(expected, sizeof expected, ",,,");
    EXPECT_EQ(line.substr(line.size() - std::min(line.size(), std::string(expected).size())), expected) << line;
  }
  // The fine volume answers deep inside it, and differently from the coarse one.
  const loader::Rgb coarse_e = loaded.ddgi_volumes()[0].sample_irradiance(at[0], {0.f, 1.f, 0.f});
  const loader::Rgb fine_e = loaded.ddgi_volumes()[1].sample_irradiance(at[0], {0.f, 1.f, 0.f});
  loader::Rgb e;
  ASSERT_TRUE(loaded.sample_ddgi(at[0], {0.f, 1.f, 0.f}, e));
  EXPECT_EQ(e, fine_e);
  EXPECT_NE(e, coarse_e);
  std::filesystem::remove_all(dir);
}

}  // namespace
