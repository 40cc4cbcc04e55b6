// What a bake holds while it runs on the Vulkan backend: the device, the scene packed for it and
// the tracer. Empty (no device touched) when the settings choose the CPU.
#pragma once
#include <memory>

#include "bake/backend.h"
#include "bake/gpu_scene.h"
#include "bake/gpu_trace.h"
#include "io/context.h"
#include "io/scene.h"

namespace gibake {

struct GpuSession {
  BackendChoice choice;
  std::unique_ptr<vk::Context> vk;  // declared first: destroyed after the tracer
  GpuSceneData scene;
  std::unique_ptr<GpuTracer> tracer;
  bool active() const { return tracer != nullptr; }
};

// Resolves the backend; on Vulkan opens the device, builds the BVH and uploads the scene. With a
// started `warmup`, its choice and device are taken instead (`settings` then only names them).
Status open_gpu_session(const Scene& scene, const BackendSettings& settings, float blend_cutoff, const Context& ctx,
                        GpuSession& out, VulkanWarmup* warmup = nullptr);

}  // namespace gibake
