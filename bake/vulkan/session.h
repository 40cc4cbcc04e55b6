// What a bake holds while it runs on the Vulkan backend: the device, the scene packed for it and
// the tracer. Empty (no device touched) when the settings choose the CPU.
#pragma once
#include <tbb/task_arena.h>

#include <memory>

#include "bake/run/arena.h"
#include "bake/run/backend.h"
#include "bake/vulkan/device_scene.h"
#include "bake/vulkan/texture_pool.h"
#include "bake/vulkan/traverse.h"
#include "io/context.h"
#include "io/scene.h"

namespace gibake {

struct GpuSession {
  BackendChoice choice;
  std::unique_ptr<vk::Context> vk;  // declared first: destroyed after the tracer
  GpuSceneData scene;
  std::unique_ptr<GpuTracer> tracer;
  // The scene's textures and mips, uploaded by the set-up beside the BVH build (null until then,
  // and for bakes that make no mips); the path tracer uses them instead of uploading its own.
  std::unique_ptr<GpuTexturePool> textures;
  // The Embree device the BVH builder uses (made by open_gpu_device, outside any arena; released
  // once the BVH is built).
  std::unique_ptr<void, void (*)(void*)> bvh_device{nullptr, nullptr};
  double open_seconds = 0.0;  // what open_gpu_device waited for the driver
  bool warmed_up = false;     // the device came from a VulkanWarmup
  // The trace's chunks in flight and rays per chunk (bake/vulkan/path_pipeline.h); 0: its defaults.
  // Internal: tests force many small chunks to check that the grouping never changes a byte.
  uint32_t in_flight = 0;
  uint64_t chunk_rays = 0;
  // Device objects a stage is done with (the trace's batch buffers: 0.03-0.05 s to free on the heavy
  // bake, docs/BENCHMARKS.md), freed beside the bake. Last: joined before anything above is destroyed.
  ReleaseBeside released;
  bool active() const { return tracer != nullptr; }
};

// A session is opened in two halves, so that the BVH build and the upload can run as a task beside
// other set-up (bake/run/bake_setup.h). open_gpu_device runs on the calling thread, outside any arena:
// the backend resolved, the device taken from `warmup` or opened, the Embree device for the BVH
// builder. build_gpu_session_scene then builds the BVH in `arena` (null: one of ctx.threads) and
// uploads the scene; it does nothing when the backend is the CPU.
Status open_gpu_device(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup = nullptr);
Status build_gpu_session_scene(const Scene& scene, float blend_cutoff, const Context& ctx, tbb::task_arena* arena,
                               GpuSession& out);

}  // namespace gibake
