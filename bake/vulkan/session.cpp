#include "bake/vulkan/session.h"
#include "io/timer.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace gibake {

namespace {
}  // namespace

Status choose_gpu_backend(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup) {
  if (warmup) {
    GIBAKE_TRY(warmup->choose(settings.workload, out.choice));
  } else {
    GIBAKE_TRY(resolve_backend(settings, out.choice));
  }
  if (out.choice.backend != Backend::Vulkan) {
    out.bvh_device.reset();
    return Status::ok();
  }
  out.in_flight = settings.vulkan_in_flight;
  out.chunk_rays = settings.vulkan_chunk_rays;
  out.pass_group_probes = settings.vulkan_pass_group_probes;
  out.bvh_cache_dir = settings.bvh_cache_dir;
  return Status::ok();
}

Status open_bvh_builder(GpuSession& out) {
  RTCDevice device = rtcNewDevice(nullptr);
  if (!device) return Status::error(ExitCode::RuntimeFailure, "", "embree", "rtcNewDevice failed");
  out.bvh_device = std::unique_ptr<void, void (*)(void*)>(device, [](void* d) { rtcReleaseDevice(static_cast<RTCDevice>(d)); });
  return Status::ok();
}

Status take_gpu_device(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup) {
  if (out.choice.backend != Backend::Vulkan) return Status::ok();
  const auto t0 = Clock::now();
  if (warmup) {
    GIBAKE_TRY(warmup->take_device(out.choice, out.vk));
  } else {
    GIBAKE_TRY(open_vulkan(out.choice, settings, out.vk));
  }
  // With a warm-up, what is left of the driver's start-up after the work it overlapped.
  out.open_seconds = seconds_since(t0);
  out.warmed_up = warmup != nullptr;
  if (out.choice.backend != Backend::Vulkan) out.bvh_device.reset();  // auto's device did not open
  return Status::ok();
}

Status open_gpu_device(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup) {
  GIBAKE_TRY(choose_gpu_backend(settings, out, warmup));
  return take_gpu_device(settings, out, warmup);
}

Status build_gpu_session_bvh(const Scene& scene, float blend_cutoff, const Context& ctx, tbb::task_arena* arena,
                             GpuSession& out) {
  if (out.choice.backend != Backend::Vulkan) return Status::ok();
  GpuSceneOptions options;
  options.blend_cutoff = blend_cutoff;
  // Embree's spatial-split build: faster traversal than a plain SAH build for a slower build
  // (docs/BENCHMARKS.md, "GPU kernels alone"); the cache makes the build a first bake's cost only.
  options.spatial_splits = true;
  options.cache_dir = out.bvh_cache_dir;
  options.embree_device = out.bvh_device.get();
  options.arena = arena;
  const auto t0 = Clock::now();
  const Status built = build_gpu_scene(scene, options, ctx, out.scene);
  out.bvh_device.reset();  // only the build needed it
  out.bvh_seconds = seconds_since(t0);
  if (!out.scene.cache_note.empty()) ctx.note(out.scene.cache_note);
  return built;
}

Status upload_gpu_session_scene(const Context& ctx, GpuSession& out) {
  if (out.choice.backend != Backend::Vulkan || !out.vk) return Status::ok();
  const auto t0 = Clock::now();
  GIBAKE_TRY(GpuTracer::create(*out.vk, out.scene, out.tracer));
  const double upload_s = seconds_since(t0);
  char line[384];
  std::snprintf(line, sizeof(line),
                "backend vulkan: %s (%s), BVH %.1f bytes per triangle, %.1f MiB on the device; instance and device "
                "%.3f s%s, BVH %s %.3f s, upload and pipeline %.3f s (%s)",
                out.choice.device.name.c_str(), out.choice.device.driver.c_str(), out.scene.bvh_bytes_per_triangle(),
                double(out.tracer->device_bytes()) / (1 << 20), out.open_seconds,
                out.warmed_up ? " (waited for the warm-up)" : "",
                out.scene.from_cache        ? "from the cache"
                : out.scene.stored_in_cache ? "build (cached)"
                                            : "build",
                out.bvh_seconds, upload_s,
                out.vk->direct_uploads() ? "written straight into device memory" : "through staging");
  ctx.note(line);
  return Status::ok();
}

}  // namespace gibake
