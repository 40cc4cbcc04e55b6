// Sky maps: equirect EXR mapping and orientation (+Y up, u = 0.5 + atan2(x, -z) / 2pi).
#include <gtest/gtest.h>

#include <OpenEXR/ImfRgbaFile.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/scene/sky.h"
#include "kernels/sh.h"

using namespace gibake;

namespace {
std::string write_exr(const std::string& name, int w, int h, float (*f)(float u, float v)) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::vector<Imf::Rgba> px(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float v = f((x + 0.5f) / w, (y + 0.5f) / h);
      px[size_t(y) * w + x] = Imf::Rgba(v, v, v, 1.f);
    }
  Imf::RgbaOutputFile file(path.c_str(), w, h, Imf::WRITE_RGBA);
  file.setFrameBuffer(px.data(), 1, w);
  file.writePixels(h);
  return path;
}

DdgiSettings empty_scene_probe(const std::string& sky) {
  DdgiSettings s;
  s.grid.explicit_bounds = true;
  s.grid.counts = {1, 1, 1};
  s.rays = 8192;
  s.relocate = false;
  s.sky_hdr = sky;
  return s;
}
}  // namespace

// Upper hemisphere of radiance 1, lower 0: E(n) = pi (1 + n.y) / 2.
TEST(DdgiSky, EquirectUpperHemisphere) {
  const std::string path = write_exr("gibake_sky_upper.exr", 256, 128, [](float, float v) { return v < 0.5f ? 1.f : 0.f; });
  Scene scene;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, empty_scene_probe(path), Context{}, r, rep));
  const float up = kernels::sh_irradiance(r.sh.data(), 2, {0, 1, 0}).x;
  const float side = kernels::sh_irradiance(r.sh.data(), 2, {1, 0, 0}).x;
  const float down = kernels::sh_irradiance(r.sh.data(), 2, {0, -1, 0}).x;
  std::printf("sky upper hemisphere: E(up) %.4f (exp %.4f) E(side) %.4f (exp %.4f) E(down) %.4f (exp 0)\n", up, M_PI,
              side, M_PI / 2, down);
  EXPECT_NEAR(up, M_PI, 0.01 * M_PI);
  EXPECT_NEAR(side, M_PI / 2, 0.01 * M_PI);
  EXPECT_NEAR(down, 0.0, 0.01 * M_PI);
  std::filesystem::remove(path);
}

// A bright patch at u = 0.75 on the horizon is +X.
TEST(DdgiSky, EquirectOrientation) {
  const std::string path = write_exr("gibake_sky_patch.exr", 128, 64, [](float u, float v) {
    return std::fabs(u - 0.75f) < 0.05f && std::fabs(v - 0.5f) < 0.1f ? 10.f : 0.f;
  });
  Sky sky;
  ASSERT_TRUE(load_sky_exr(path, sky));
  EXPECT_GT(sky.radiance({1, 0, 0}).x, 9.f);
  EXPECT_EQ(sky.radiance({-1, 0, 0}).x, 0.f);
  EXPECT_EQ(sky.radiance({0, 0, -1}).x, 0.f);
  Scene scene;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, empty_scene_probe(path), Context{}, r, rep));
  // SH band 1 order is (y, z, x): the x coefficient dominates and is positive.
  EXPECT_GT(r.sh[3 * 3], 0.f);
  EXPECT_GT(r.sh[3 * 3], 5 * std::fabs(r.sh[1 * 3]));
  EXPECT_GT(r.sh[3 * 3], 5 * std::fabs(r.sh[2 * 3]));
  std::filesystem::remove(path);
}
