// What several Vulkan tests build alike: the floor-and-wall scene with its small probe grid, and a
// CPU (Embree) and GPU tracer over one scene.
#pragma once
#include <gtest/gtest.h>

#include <memory>

#include "bake/ddgi/ddgi.h"
#include "bake/scene/prepare.h"
#include "bake/vulkan/device_scene.h"
#include "bake/vulkan/traverse.h"
#include "kernels/vulkan/context.h"
#include "tests/bake/scene_builders.h"

namespace gibake::test {

// A single-sided floor (albedo 0.5) and a double-sided wall at x = 1.1.
inline Scene floor_and_wall() {
  Scene scene;
  add_quad(scene, {-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}, {0, 1, 0}, add_material(scene, 0.5f));
  add_quad(scene, {1.1f, 0, -10}, {1.1f, 0, 10}, {1.1f, 5, 10}, {1.1f, 5, -10}, {-1, 0, 0},
           add_material(scene, 0.5f, 0.f, true));
  return scene;
}

// 3x3x3 probes over the floor, the bottom ones 1 cm above it, under a white sky.
inline DdgiSettings floor_and_wall_grid(uint32_t rays) {
  DdgiSettings s;
  s.grid.explicit_bounds = true;
  s.grid.grid_min = {-1, 0.01f, -1};
  s.grid.grid_max = {1, 2.01f, 1};
  s.grid.counts = {3, 3, 3};
  s.rays = rays;
  s.sky = {1, 1, 1};
  return s;
}

struct Tracers {
  std::unique_ptr<PreparedScene> cpu;
  GpuSceneData data;
  std::unique_ptr<GpuTracer> gpu;
};

// Both tracers over `scene` (which must outlive them); false (with a test failure) when either fails.
inline bool make_tracers(vk::Context& vk, const Scene& scene, Tracers& out, uint32_t batch_rays = 1u << 20) {
  Context ctx;
  const Status cpu = PreparedScene::create(scene, ctx, out.cpu);
  EXPECT_TRUE(cpu) << cpu.message();
  const Status built = build_gpu_scene(scene, {}, ctx, out.data);
  EXPECT_TRUE(built) << built.message();
  const Status gpu = built ? GpuTracer::create(vk, out.data, out.gpu, batch_rays) : built;
  EXPECT_TRUE(gpu) << gpu.message();
  return cpu && gpu;
}

}  // namespace gibake::test
