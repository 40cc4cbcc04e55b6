// Helpers for the voxel-GI tests: bake a scene built in code and open the bytes with the loader.
#pragma once
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "bake/scene/prepare.h"
#include "bake/scene/lights.h"
#include "bake/vxgi/vxgi.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"

namespace gibake::test {

struct VxgiBake {
  VxgiResult result;
  std::vector<uint8_t> bytes;
  loader::BakeFile file;
  const loader::VxgiVolume& volume() const { return file.vxgi_volumes().at(0); }
};

// Settings of a quick test bake: direct light only (bounces 0), no calibration.
inline VxgiSettings quick_settings(int resolution, uint32_t rays) {
  VxgiSettings s;
  s.resolution = resolution;
  s.rays = rays;
  s.bounces = 0;
  s.calibration_points = 0;
  return s;
}

inline void bake_vxgi_scene(const Scene& scene, const VxgiSettings& settings, VxgiBake& out,
                            const std::vector<SunLight>& suns = {}) {
  Context ctx;
  ctx.threads = 2;
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(scene, ctx, prepared).is_ok());
  Sky sky;
  ASSERT_TRUE(bake_vxgi(scene, *prepared, shade_lights(scene, suns), sky, settings, ctx, out.result).is_ok());
  BakeOutputs outputs;
  outputs.vxgi = &out.result;
  BakeFileOptions options;
  options.vxgi = FloatPrecision::Full;
  ASSERT_TRUE(build_bake_file(outputs, options, out.bytes).is_ok());
  ASSERT_FALSE(out.file.open_borrowed(out.bytes.data(), out.bytes.size()));
  ASSERT_EQ(out.file.vxgi_volumes().size(), size_t(settings.clipmaps));
}

// The bake file's bytes at `threads` worker threads (no lights, no sky): determinism checks.
inline void vxgi_file_bytes(const Scene& scene, const VxgiSettings& settings, int threads, std::vector<uint8_t>& bytes) {
  Context ctx;
  ctx.threads = threads;
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(scene, ctx, prepared).is_ok());
  VxgiResult result;
  ASSERT_TRUE(bake_vxgi(scene, *prepared, {}, Sky{}, settings, ctx, result).is_ok());
  BakeOutputs outputs;
  outputs.vxgi = &result;
  ASSERT_TRUE(build_bake_file(outputs, BakeFileOptions{}, bytes).is_ok());
}

// Determinism: the bake file's bytes at 1 and at 2 worker threads are the same.
inline void expect_same_bytes_for_any_threads(const Scene& scene, const VxgiSettings& settings) {
  std::vector<uint8_t> one, two;
  vxgi_file_bytes(scene, settings, 1, one);
  vxgi_file_bytes(scene, settings, 2, two);
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(one, two);
}

}  // namespace gibake::test
