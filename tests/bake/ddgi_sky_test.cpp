// Sky maps: equirect EXR mapping and orientation (+Y up, u = 0.5 + atan2(x, -z) / 2pi).
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfRgbaFile.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

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

// A map of 32-bit float channels `names`, every value f(u, v) (the same in each channel).
std::string write_float_exr(const std::string& name, int w, int h, const std::vector<const char*>& names,
                            float (*f)(float u, float v)) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::vector<float> px(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) px[size_t(y) * w + x] = f((x + 0.5f) / w, (y + 0.5f) / h);
  Imf::Header header(w, h);
  Imf::FrameBuffer fb;
  for (const char* c : names) {
    header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    fb.insert(c, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px.data()), sizeof(float), sizeof(float) * w));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(fb);
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

// A sunlit sky's values lie far above a half float's 65504: read at full precision, an upper
// hemisphere of 1e6 cd/m^2 gives E(up) = pi 1e6 lux, not the black of an overflowed half.
TEST(DdgiSky, FloatMapsKeepValuesBeyondHalfFloats) {
  const std::string path = write_float_exr("gibake_sky_bright.exr", 64, 32, {"R", "G", "B"},
                                           [](float, float v) { return v < 0.5f ? 1e6f : 0.f; });
  Sky sky;
  ASSERT_TRUE(load_sky_exr(path, sky));
  EXPECT_FLOAT_EQ(sky.radiance({0, 1, 0}).x, 1e6f);
  EXPECT_EQ(sky.replaced_values, 0u);
  Scene scene;
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, empty_scene_probe(path), Context{}, r, rep));
  EXPECT_NEAR(kernels::sh_irradiance(r.sh.data(), 2, {0, 1, 0}).x, M_PI * 1e6, 0.01 * M_PI * 1e6);
  std::filesystem::remove(path);
}

// Values the sampler cannot use (NaN, infinite, negative) read as 0 and are counted for the caller
// to report; a map without colour channels, and a FIFO in place of a file, are refused.
TEST(DdgiSky, UnusableMapsAreRefusedOrCounted) {
  const std::string bad = write_float_exr("gibake_sky_bad.exr", 8, 4, {"R", "G", "B"}, [](float u, float) {
    return u < 0.25f ? std::nanf("") : u < 0.5f ? -2.f : u < 0.75f ? INFINITY : 3.f;
  });
  Sky sky;
  ASSERT_TRUE(load_sky_exr(bad, sky));
  EXPECT_EQ(sky.replaced_values, 3u * 3u * 2u * 4u);              // three columns of 2 x 4 pixels, 3 channels each
  EXPECT_EQ(sky.radiance({0.7071f, 0.f, -0.7071f}).x, 0.f);       // u = 0.625: the infinite columns
  EXPECT_FLOAT_EQ(sky.radiance({0.7071f, 0.f, 0.7071f}).x, 3.f);  // u = 0.875: the last two
  const std::string alpha = write_float_exr("gibake_sky_alpha.exr", 8, 4, {"A"}, [](float, float) { return 1.f; });
  Status st = load_sky_exr(alpha, sky);
  EXPECT_EQ(st.code(), ExitCode::InvalidInput);
  EXPECT_NE(st.message().find("no R, G and B (or Y) channels"), std::string::npos) << st.message();
  const std::string fifo = (std::filesystem::temp_directory_path() / "gibake_sky_fifo.exr").string();
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  st = load_sky_exr(fifo, sky);  // would block on the open
  EXPECT_EQ(st.code(), ExitCode::IoFailure);
  EXPECT_NE(st.message().find("not a regular file"), std::string::npos) << st.message();
  for (const std::string& p : {bad, alpha, fifo}) std::filesystem::remove(p);
}
