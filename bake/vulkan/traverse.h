// Ray traversal on a Vulkan device: the GPU twin of PreparedScene::intersect / occluded for whole
// batches of rays (kernels/shaders/traverse.comp over a GpuSceneData BVH). Rays stream through a
// fixed-size device batch, so any number of rays runs in bounded device memory.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "bake/vulkan/device_scene.h"
#include "io/status.h"
#include "kernels/vulkan/context.h"

namespace gibake {

class GpuTracer {
 public:
  ~GpuTracer();
  GpuTracer(const GpuTracer&) = delete;
  GpuTracer& operator=(const GpuTracer&) = delete;

  // Uploads the scene. Fails (RuntimeFailure, naming the bytes needed and the device's memory)
  // when the scene and one batch do not fit. `batch_rays`: rays per dispatch.
  static Status create(vk::Context& vk, const GpuSceneData& scene, std::unique_ptr<GpuTracer>& out,
                       uint32_t batch_rays = 1u << 20);

  // Closest hits (t < 0: miss; triangle = Scene triangle; u, v as Embree).
  Status intersect(const std::vector<gpu::GpuRay>& rays, std::vector<gpu::GpuHit>& hits, double* gpu_seconds = nullptr);
  // 1 where something blocks the ray within [tmin, tmax], else 0.
  Status occluded(const std::vector<gpu::GpuRay>& rays, std::vector<uint32_t>& blocked, double* gpu_seconds = nullptr);

  uint64_t device_bytes() const { return device_bytes_; }
  vk::Context& context() const { return vk_; }
  // The closest-hit dispatch over `n` rays already on the device (GpuRay), writing GpuHits: for
  // kernels that make rays and read hits without a round trip through the host.
  vk::Dispatch closest_hits(const vk::Buffer& rays, vk::Buffer& hits, uint32_t n) const;

 private:
  friend class GpuPathTracer;  // traces over the same scene buffers
  explicit GpuTracer(vk::Context& vk) : vk_(vk) {}
  Status trace(const std::vector<gpu::GpuRay>& rays, uint32_t mode, void* out, size_t out_stride, double* gpu_seconds);

  vk::Context& vk_;
  uint32_t root_ = GPU_NO_ROOT;
  uint32_t batch_ = 0;
  uint64_t device_bytes_ = 0;
  vk::Buffer nodes_, tris_, alpha_tris_, materials_, textures_, texels_, rays_, results_;
  // Each triangle record's Scene triangle and alpha slot, in record order (kept on the host so that
  // the path tracer's set-up does not read them back from the device).
  std::vector<uint32_t> record_triangle_, record_alpha_;
  vk::Pipeline traverse_;
};

}  // namespace gibake
