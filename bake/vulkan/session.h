// What a bake holds while it runs on the Vulkan backend: the device, the scene packed for it and
// the tracer. Empty (no device touched) when the settings choose the CPU.
#pragma once
#include <tbb/task_arena.h>

#include <memory>

#include "bake/run/arena.h"
#include "bake/run/backend.h"
#include "bake/vulkan/device_scene.h"
#include "bake/vulkan/path.h"
#include "bake/vulkan/relocate.h"
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
  // The last DDGI trace's path tracer (its shading data and pipelines; its ray batches released),
  // kept after the trace for the reconstruction check's reference paths (bake/vulkan/reference_paths.h).
  std::unique_ptr<GpuPathTracer> reference_tracer;
  // The last relocation's kernels and buffers, handed back when its passes end: the next volume
  // relocated before a trace ends reuses them when they serve it (GpuRelocation::serves); the end
  // of a trace releases them, so that at most one set is held and none during the fit.
  std::unique_ptr<GpuRelocation> relocation;
  // The Embree device the BVH builder uses (made by open_gpu_device, outside any arena; released
  // once the BVH is built).
  std::unique_ptr<void, void (*)(void*)> bvh_device{nullptr, nullptr};
  double open_seconds = 0.0;  // what take_gpu_device waited for the driver
  double bvh_seconds = 0.0;   // the BVH's build on the host
  bool warmed_up = false;     // the device came from a VulkanWarmup
  // The trace's chunks in flight and rays per chunk (bake/vulkan/path_pipeline.h); 0: its defaults.
  // Internal: tests force many small chunks to check that the grouping never changes a byte.
  uint32_t in_flight = 0;
  uint64_t chunk_rays = 0;
  uint32_t pass_group_probes = 0;  // BackendSettings::vulkan_pass_group_probes
  std::string bvh_cache_dir;  // BackendSettings::bvh_cache_dir
  // Device objects a stage is done with (the trace's batch buffers, slow to free when large), freed
  // beside the bake. Last: joined before anything above is destroyed.
  ReleaseBeside released;
  bool active() const { return tracer != nullptr; }
};

// A session is opened in steps, so that the host's share of the set-up (the BVH build, the textures'
// packing) runs while the driver is still opening the device (bake/pipeline/bake_setup.h):
// - open_bvh_builder, outside any arena: the Embree device the BVH builder uses (made before the
//   choice so that the choice can wait for the listing inside the set-up's arena; released when the
//   choice is the CPU);
// - choose_gpu_backend: the backend resolved (from `warmup` once it has listed the devices,
//   without waiting for the device);
// - build_gpu_session_bvh: the BVH built in `arena` (null: one of ctx.threads), no device needed;
// - take_gpu_device: waits for the device (`auto`: one that did not open turns the choice into the
//   CPU's);
// - upload_gpu_session_scene: the BVH uploaded, the session's note.
// Each does nothing when the backend is (or became) the CPU. open_gpu_device is choose and take.
Status open_bvh_builder(GpuSession& out);
Status choose_gpu_backend(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup = nullptr);
Status take_gpu_device(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup = nullptr);
Status open_gpu_device(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup = nullptr);
Status build_gpu_session_bvh(const Scene& scene, float blend_cutoff, const Context& ctx, tbb::task_arena* arena,
                             GpuSession& out);
Status upload_gpu_session_scene(const Context& ctx, GpuSession& out);

}  // namespace gibake
