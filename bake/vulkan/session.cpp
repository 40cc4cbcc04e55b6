#include "bake/vulkan/session.h"
#include "io/timer.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace gibake {

namespace {
}  // namespace

Status open_gpu_device(const BackendSettings& settings, GpuSession& out, VulkanWarmup* warmup) {
  const auto t0 = Clock::now();
  if (warmup) {
    GIBAKE_TRY(warmup->take(settings.workload, out.choice, out.vk));
  } else {
    GIBAKE_TRY(resolve_backend(settings, out.choice));
    if (out.choice.backend == Backend::Vulkan) GIBAKE_TRY(open_vulkan(out.choice, settings, out.vk));
  }
  if (out.choice.backend != Backend::Vulkan) return Status::ok();
  // With a warm-up, what is left of the driver's start-up after the work it overlapped.
  out.open_seconds = seconds_since(t0);
  out.warmed_up = warmup != nullptr;
  out.in_flight = settings.vulkan_in_flight;
  out.chunk_rays = settings.vulkan_chunk_rays;
  RTCDevice device = rtcNewDevice(nullptr);
  if (!device) return Status::error(ExitCode::RuntimeFailure, "", "embree", "rtcNewDevice failed");
  out.bvh_device = std::unique_ptr<void, void (*)(void*)>(device, [](void* d) { rtcReleaseDevice(static_cast<RTCDevice>(d)); });
  return Status::ok();
}

Status build_gpu_session_scene(const Scene& scene, float blend_cutoff, const Context& ctx, tbb::task_arena* arena,
                               GpuSession& out) {
  if (out.choice.backend != Backend::Vulkan || !out.vk) return Status::ok();
  GpuSceneOptions options;
  options.blend_cutoff = blend_cutoff;
  // Embree's spatial-split build gives 1.5x faster traversal (H100: 2.94 against 1.89 G closest-hit
  // rays/s) but, measured in whole bakes on the H100 (docs/BENCHMARKS.md, 2026-11-25), it takes
  // 0.27-0.37 s against 0.08-0.10 s on 16 threads and saves only 15% of the path kernels' time
  // (0.94 -> 0.81 s on 80,640 probes x 2,048 rays): every bake of the table came out slower.
  options.spatial_splits = false;
  options.embree_device = out.bvh_device.get();
  options.arena = arena;
  auto t0 = Clock::now();
  const Status built = build_gpu_scene(scene, options, ctx, out.scene);
  out.bvh_device.reset();  // only the build needed it
  GIBAKE_TRY(built);
  const double bvh_s = seconds_since(t0);
  t0 = Clock::now();
  GIBAKE_TRY(GpuTracer::create(*out.vk, out.scene, out.tracer));
  const double upload_s = seconds_since(t0);
  char line[384];
  std::snprintf(line, sizeof(line),
                "backend vulkan: %s (%s), BVH %.1f bytes per triangle, %.1f MiB on the device; instance and device "
                "%.3f s%s, BVH build %.3f s, upload and pipeline %.3f s",
                out.choice.device.name.c_str(), out.choice.device.driver.c_str(), out.scene.bvh_bytes_per_triangle(),
                double(out.tracer->device_bytes()) / (1 << 20), out.open_seconds,
                out.warmed_up ? " (waited for the warm-up)" : "", bvh_s, upload_s);
  ctx.note(line);
  return Status::ok();
}

}  // namespace gibake
