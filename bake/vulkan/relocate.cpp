#include "bake/vulkan/relocate.h"

#include <algorithm>
#include <cstring>

#include "kernels/shaders/reloc_sums_spv.h"

namespace gibake {
using kernels::float3;

std::vector<gpu::GpuRelocTri> reloc_triangles(const Scene& scene) {
  const size_t n = scene.indices.size() / 3;
  std::vector<gpu::GpuRelocTri> out(std::max<size_t>(n, 1), gpu::GpuRelocTri{{0.f, 0.f, 0.f, 0.f}});
  for (size_t t = 0; t < n; ++t) {
    const uint32_t* idx = &scene.indices[t * 3];
    const float3 v0 = kernels::load3(&scene.positions[size_t(idx[0]) * 3]);
    const float3 v1 = kernels::load3(&scene.positions[size_t(idx[1]) * 3]);
    const float3 v2 = kernels::load3(&scene.positions[size_t(idx[2]) * 3]);
    const float3 ng = kernels::cross(v1 - v0, v2 - v0);  // geometry_record's, bit for bit
    const int32_t m = t < scene.tri_material.size() ? scene.tri_material[t] : -1;
    const bool ds = m >= 0 && size_t(m) < scene.materials.size() && scene.materials[size_t(m)].double_sided;
    out[t].ng = {ng.x, ng.y, ng.z, ds ? 1.f : 0.f};
  }
  return out;
}

Status GpuRelocation::create(GpuTracer& tracer, const Scene& scene, const float* fibonacci, uint32_t rays,
                             std::unique_ptr<GpuRelocation>& out, uint64_t chunk_rays) {
  out.reset();
  vk::Context& vk = tracer.context();
  if (!vk.shader_float64() || rays == 0) return Status::ok();
  std::unique_ptr<GpuRelocation> g(new GpuRelocation(tracer));
  g->rays_ = rays;
  g->chunk_probes_ = std::max<size_t>(1, size_t(chunk_rays / rays));
  GIBAKE_TRY(GpuRayGen::create(vk, g->raygen_));
  GIBAKE_TRY(g->raygen_->set_fibonacci(fibonacci, rays));
  const std::vector<gpu::GpuRelocTri> tris = reloc_triangles(scene);
  GIBAKE_TRY(vk.create_buffer(tris.size() * sizeof(gpu::GpuRelocTri), g->tris_, "relocation triangles"));
  GIBAKE_TRY(vk.upload(g->tris_, tris.data(), tris.size() * sizeof(gpu::GpuRelocTri)));
  const uint64_t chunk_ray_count = uint64_t(g->chunk_probes_) * rays;
  GIBAKE_TRY(vk.create_buffer(chunk_ray_count * sizeof(gpu::GpuRay), g->rays_buf_, "relocation rays"));
  GIBAKE_TRY(vk.create_buffer(chunk_ray_count * sizeof(gpu::GpuHit), g->hits_, "relocation hits"));
  GIBAKE_TRY(vk.create_buffer(g->chunk_probes_ * sizeof(gpu::GpuRelocSums), g->sums_, "relocation sums"));
  GIBAKE_TRY(vk.create_pipeline(shaders::reloc_sums_spv, sizeof(shaders::reloc_sums_spv) / 4, 4,
                                sizeof(gpu::RelocSumsPush), g->pipeline_, "reloc_sums"));
  out = std::move(g);
  return Status::ok();
}

namespace {
RelocationSums unpack(const gpu::GpuRelocSums& g) {
  RelocationSums s;
  s.delta[0] = gpu::double_from_words(g.delta_xy.x, g.delta_xy.y);
  s.delta[1] = gpu::double_from_words(g.delta_xy.z, g.delta_xy.w);
  s.delta[2] = gpu::double_from_words(g.delta_z_close.x, g.delta_z_close.y);
  std::memcpy(&s.nearest, &g.delta_z_close.z, 4);
  s.close = g.delta_z_close.w != 0u;
  return s;
}
}  // namespace

// One chunk in one submission: rays, hits and sums stay on the device.
Status GpuRelocation::chunk(const std::vector<gpu::GpuRayGenProbe>& records, float threshold, RelocationSums* out) {
  vk::Context& vk = tracer_.context();
  const uint32_t probes = uint32_t(records.size());
  const uint32_t n = probes * rays_;
  GIBAKE_TRY(raygen_->set_probes(records));
  const gpu::RelocSumsPush push{{probes, rays_, 0u, 0u}, {threshold, 0.f, 0.f, 0.f}};
  vk::Dispatch sums;
  sums.pipeline = &pipeline_;
  sums.buffers = {&tris_, &rays_buf_, &hits_, &sums_};
  sums.push = vk::push_bytes(push);
  sums.groups[0] = (probes + 63) / 64;
  GIBAKE_TRY(vk.run({raygen_->dispatch(rays_buf_, 0, n, 0, true), tracer_.closest_hits(rays_buf_, hits_, n), sums}));
  std::vector<gpu::GpuRelocSums> g(probes);
  GIBAKE_TRY(vk.download(sums_, g.data(), g.size() * sizeof(gpu::GpuRelocSums)));
  for (uint32_t i = 0; i < probes; ++i) out[i] = unpack(g[i]);
  return Status::ok();
}

Status GpuRelocation::sums(const std::vector<int32_t>& probes, uint64_t seed, uint32_t pass,
                           const std::function<float3(int32_t)>& origin, float threshold,
                           std::vector<RelocationSums>& out) {
  out.assign(probes.size(), RelocationSums{});
  std::vector<gpu::GpuRayGenProbe> records;
  for (size_t first = 0; first < probes.size(); first += chunk_probes_) {
    const size_t count = std::min(chunk_probes_, probes.size() - first);
    records.resize(count);
    for (size_t i = 0; i < count; ++i) {
      const int32_t p = probes[first + i];
      records[i] = raygen_probe(origin(p), seed, uint32_t(p), pass);
    }
    GIBAKE_TRY(chunk(records, threshold, &out[first]));
  }
  return Status::ok();
}

}  // namespace gibake
