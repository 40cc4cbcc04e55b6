#include "bake/vulkan/relocate.h"

#include <algorithm>
#include <cstring>

#include "bake/vulkan/pipelines.h"

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
  g->scene_ = &scene;
  g->fibonacci_.assign(fibonacci, fibonacci + size_t(rays) * 3);
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
  GIBAKE_TRY(vk.create_pipeline(pipelines::reloc_sums(), g->pipeline_));
  out = std::move(g);
  return Status::ok();
}

bool GpuRelocation::serves(const GpuTracer& tracer, const Scene& scene, const float* fibonacci, uint32_t rays) const {
  return &tracer == &tracer_ && &scene == scene_ && rays == rays_ &&
         std::equal(fibonacci_.begin(), fibonacci_.end(), fibonacci);
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

std::vector<vk::Dispatch> GpuRelocation::sums_dispatches(uint32_t probes, float threshold) {
  std::vector<vk::Dispatch> out;
  for (uint32_t w = 0; w == 0 || w < rays_; w += GPU_RAY_WINDOW) {  // a window of each probe's rays
    const gpu::RelocSumsPush push{{probes, rays_, w, GPU_RAY_WINDOW}, {threshold, 0.f, 0.f, 0.f}};
    vk::Dispatch sums;
    sums.pipeline = &pipeline_;
    sums.buffers = {&tris_, &rays_buf_, &hits_, &sums_};
    sums.push = vk::push_bytes(push);
    sums.flat_groups = (probes + 63) / 64;
    out.push_back(std::move(sums));
  }
  return out;
}

// Each chunk is one recording (its probe records uploaded, its rays made, traced and summed, the
// sums read back): one submission where there were three round trips, and two chunks in flight, so
// that the host fills the next chunk and unpacks the last while the device traces. The chunks share
// the device buffers: one queue runs the recordings in order, each after a barrier
// (kernels/vulkan/recording.cpp). Every probe's sums are its own, so chunking never changes them.
Status GpuRelocation::sums(const std::vector<int32_t>& probes, uint64_t seed, uint32_t pass,
                           const std::function<float3(int32_t)>& origin, float threshold,
                           std::vector<RelocationSums>& out) {
  out.assign(probes.size(), RelocationSums{});
  if (probes.empty()) return Status::ok();
  vk::Context& vk = tracer_.context();
  GIBAKE_TRY(raygen_->reserve_probes(std::min(chunk_probes_, probes.size())));  // before any is in flight
  struct Chunk {
    vk::Recording& rec;
    size_t first = 0, count = 0, download = 0;
  };
  Chunk chunks[2] = {{recordings_[0]}, {recordings_[1]}};
  std::vector<gpu::GpuRayGenProbe> records;
  const auto start = [&](Chunk& c, size_t first) -> Status {
    c.first = first;
    c.count = std::min(chunk_probes_, probes.size() - first);
    records.resize(c.count);
    for (size_t i = 0; i < c.count; ++i) {
      const int32_t p = probes[first + i];
      records[i] = raygen_probe(origin(p), seed, uint32_t(p), pass);
    }
    GIBAKE_TRY(raygen_->record_probes(records, c.rec));
    const uint32_t n = uint32_t(c.count) * rays_;
    c.rec.dispatch(raygen_->dispatch(rays_buf_, 0, n, 0, true));
    c.rec.dispatch(tracer_.closest_hits(rays_buf_, hits_, n));
    for (vk::Dispatch& d : sums_dispatches(uint32_t(c.count), threshold)) c.rec.dispatch(std::move(d));
    c.download = c.rec.download(sums_, c.count * sizeof(gpu::GpuRelocSums));
    return vk.submit(c.rec);
  };
  const auto finish = [&](Chunk& c) -> Status {
    GIBAKE_TRY(vk.wait(c.rec));
    const auto* g = static_cast<const gpu::GpuRelocSums*>(c.rec.result(c.download));
    for (size_t i = 0; i < c.count; ++i) out[c.first + i] = unpack(g[i]);
    return Status::ok();
  };
  const size_t count = (probes.size() + chunk_probes_ - 1) / chunk_probes_;
  GIBAKE_TRY(start(chunks[0], 0));
  for (size_t k = 0; k < count; ++k) {
    if (k + 1 < count) GIBAKE_TRY(start(chunks[(k + 1) % 2], (k + 1) * chunk_probes_));
    GIBAKE_TRY(finish(chunks[k % 2]));
  }
  return Status::ok();
}

}  // namespace gibake
