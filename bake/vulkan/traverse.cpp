#include "bake/vulkan/traverse.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "bake/vulkan/pipelines.h"

namespace gibake {

GpuTracer::~GpuTracer() = default;

Status GpuTracer::create(vk::Context& vk, const GpuSceneData& scene, std::unique_ptr<GpuTracer>& out,
                         uint32_t batch_rays) {
  std::unique_ptr<GpuTracer> t(new GpuTracer(vk));
  t->root_ = scene.root;
  t->batch_ = std::max<uint32_t>(64, batch_rays);
  // The scene cannot shrink; the batch halves until both fit (more dispatches, the same hits).
  const uint64_t per_ray = sizeof(gpu::GpuRay) + sizeof(gpu::GpuHit);
  while (t->batch_ > 64 && scene.bytes() + uint64_t(t->batch_) * per_ray > vk.device_memory()) t->batch_ /= 2;
  const uint64_t need = scene.bytes() + uint64_t(t->batch_) * per_ray;
  GIBAKE_TRY(vk.check_device_memory(need, 0, "the scene's BVH and triangles with one ray batch",
                                     "the scene decides it: --backend cpu bakes without the device"));
  uint64_t& total = t->device_bytes_;
  GIBAKE_TRY(vk.create_filled_buffer(scene.nodes, t->nodes_, "BVH nodes", total));
  GIBAKE_TRY(vk.create_filled_buffer(scene.triangles, t->tris_, "triangles", total));
  t->record_triangle_.resize(scene.triangles.size());
  t->record_alpha_.resize(scene.triangles.size());
  for (size_t i = 0; i < scene.triangles.size(); ++i) {
    std::memcpy(&t->record_triangle_[i], &scene.triangles[i].v0.w, 4);
    std::memcpy(&t->record_alpha_[i], &scene.triangles[i].v1.w, 4);
  }
  GIBAKE_TRY(vk.create_filled_buffer(scene.alpha_triangles, t->alpha_tris_, "alpha triangles", total));
  GIBAKE_TRY(vk.create_filled_buffer(scene.materials, t->materials_, "materials", total));
  GIBAKE_TRY(vk.create_filled_buffer(scene.textures, t->textures_, "textures", total));
  GIBAKE_TRY(vk.create_filled_buffer(scene.texels, t->texels_, "texels", total));
  GIBAKE_TRY(vk.create_buffer(uint64_t(t->batch_) * sizeof(gpu::GpuRay), t->rays_, "ray batch"));
  GIBAKE_TRY(vk.create_buffer(uint64_t(t->batch_) * sizeof(gpu::GpuHit), t->results_, "hit batch"));
  total += uint64_t(t->batch_) * per_ray;
  GIBAKE_TRY(vk.create_pipeline(pipelines::traverse(), t->traverse_));
  out = std::move(t);
  return Status::ok();
}

Status GpuTracer::trace(const std::vector<gpu::GpuRay>& rays, uint32_t mode, void* out, size_t out_stride,
                        double* gpu_seconds) {
  if (gpu_seconds) *gpu_seconds = 0.0;
  for (size_t first = 0; first < rays.size(); first += batch_) {
    const uint32_t n = static_cast<uint32_t>(std::min<size_t>(batch_, rays.size() - first));
    GIBAKE_TRY(vk_.upload(rays_, &rays[first], uint64_t(n) * sizeof(gpu::GpuRay)));
    gpu::TraversePush push{{n, mode, root_, 0u}};
    vk::Dispatch d;
    d.pipeline = &traverse_;
    d.buffers = {&nodes_, &tris_, &alpha_tris_, &materials_, &textures_, &texels_, &rays_, &results_};
    d.push = vk::push_bytes(push);
    d.flat_groups = (n + 63) / 64;
    std::vector<double> seconds;
    GIBAKE_TRY(vk_.run({d}, &seconds));
    if (gpu_seconds) *gpu_seconds += seconds[0];
    GIBAKE_TRY(vk_.download(results_, static_cast<uint8_t*>(out) + first * out_stride, uint64_t(n) * out_stride));
  }
  return Status::ok();
}

vk::Dispatch GpuTracer::closest_hits(const vk::Buffer& rays, vk::Buffer& hits, uint32_t n) const {
  const gpu::TraversePush push{{n, 0u, root_, 0u}};
  vk::Dispatch d;
  d.pipeline = &traverse_;
  d.buffers = {&nodes_, &tris_, &alpha_tris_, &materials_, &textures_, &texels_, &rays, &hits};
  d.push = vk::push_bytes(push);
  d.flat_groups = (n + 63) / 64;
  return d;
}

Status GpuTracer::intersect(const std::vector<gpu::GpuRay>& rays, std::vector<gpu::GpuHit>& hits, double* gpu_seconds) {
  hits.resize(rays.size());
  return trace(rays, 0, hits.data(), sizeof(gpu::GpuHit), gpu_seconds);
}

Status GpuTracer::occluded(const std::vector<gpu::GpuRay>& rays, std::vector<uint32_t>& blocked, double* gpu_seconds) {
  blocked.resize(rays.size());
  return trace(rays, 1, blocked.data(), sizeof(uint32_t), gpu_seconds);
}

}  // namespace gibake
