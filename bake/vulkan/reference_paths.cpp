#include "bake/vulkan/reference_paths.h"

#include <tbb/parallel_for.h>
#include <xxhash.h>

#include <algorithm>
#include <cstring>

#include "bake/vulkan/path.h"

namespace gibake {

Status GpuPathTracer::trace_radiance(const gpu::GpuPathRay* rays, uint32_t n, const RadianceParams& p,
                                     gpu::GpuPathBrief* out) {
  if (n == 0) return Status::ok();
  if (n > max_batch_)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "more reference paths than one batch holds");
  GIBAKE_TRY(reserve_batch(n));
  gpu::GpuPathParams params = params_;
  params.counts.x = n;
  params.flags.x = 0u;  // trace_radiance evaluates every light at each vertex
  params.flags.y = uint32_t(std::max(0, p.bounces));
  params.flags.z = uint32_t(std::max(0, p.roulette_depth));
  params.sky_map.z = 2u;  // mode 2: radiance along each ray, rays in order
  params.sky_map.w = 0u;  // no emitter samples paired with the rays
  params.misc.x = p.cone_spread;
  params.misc.y = p.shadow_bias;
  params.misc.w = 0.f;
  // Briefs, no integration samples; one "ray per probe" so that no lane order applies.
  const gpu::PathPush push{{0u, 0u, 1u, 1u}, {0.f, 0.f, 0.f, 0.f}};
  vk::Context& vk = bvh_.vk_;
  vk::Recording rec;
  rec.upload(rays_, rays, uint64_t(n) * sizeof(gpu::GpuPathRay));
  rec.upload(params_buf_, &params, sizeof(params));
  rec.dispatch(path_dispatch(push, nullptr, nullptr, n));
  const size_t briefs = rec.download(briefs_, uint64_t(n) * sizeof(gpu::GpuPathBrief));
  GIBAKE_TRY(vk.submit(rec));
  GIBAKE_TRY(vk.wait(rec));
  std::memcpy(out, rec.result(briefs), uint64_t(n) * sizeof(gpu::GpuPathBrief));
  return Status::ok();
}

bool GpuPathTracer::lit_by(const std::vector<kernels::ShadeLight>& lights, const Sky& sky) const {
  if (lights.size() != host_lights_.size() ||
      (!lights.empty() && std::memcmp(lights.data(), host_lights_.data(), lights.size() * sizeof(lights[0])) != 0))
    return false;
  const bool map = !sky.rgb.empty();
  if (params_.sky.x != sky.constant.x || params_.sky.y != sky.constant.y || params_.sky.z != sky.constant.z ||
      params_.sky.w != sky.scale)
    return false;
  if (params_.sky_map.x != (map ? uint32_t(sky.width) : 0u) || params_.sky_map.y != (map ? uint32_t(sky.height) : 0u))
    return false;
  return !map || XXH3_64bits(sky.rgb.data(), sky.rgb.size() * sizeof(float)) == sky_map_hash_;
}

namespace {

class GpuReferencePaths final : public ReferencePathDevice {
 public:
  explicit GpuReferencePaths(std::shared_ptr<GpuSession> session) : session_(std::move(session)) {}

  bool lights_match(const std::vector<kernels::ShadeLight>& lights, const Sky& sky) const override {
    return tracer().lit_by(lights, sky);
  }
  uint64_t max_rays() const override { return tracer().max_batch_rays(); }
  std::string name() const override { return session_->vk->device().name; }

  Status trace(const std::vector<ReferenceRay>& rays, const ReferencePathParams& p,
               std::vector<ReferenceRadiance>& out) override {
    GpuPathTracer::RadianceParams params;
    params.bounces = p.bounces;
    params.roulette_depth = p.roulette_depth;
    params.cone_spread = p.cone_spread;
    params.shadow_bias = p.shadow_bias;
    const size_t n = rays.size();
    gpu_rays_.resize(n);
    briefs_.resize(n);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
      const ReferenceRay& r = rays[i];
      gpu_rays_[i] = {{r.origin.x, r.origin.y, r.origin.z, 0.f},
                      {r.dir.x, r.dir.y, r.dir.z, 0.f},
                      {uint32_t(r.key), uint32_t(r.key >> 32), 0u, 0u}};
    });
    const uint32_t batch = tracer().max_batch_rays();
    for (size_t first = 0; first < n; first += batch) {
      const uint32_t count = uint32_t(std::min<size_t>(batch, n - first));
      GIBAKE_TRY(tracer().trace_radiance(&gpu_rays_[first], count, params, &briefs_[first]));
    }
    out.resize(n);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
      const gpu::GpuPathBrief& b = briefs_[i];
      out[i] = {kernels::float3{b.radiance_t.x, b.radiance_t.y, b.radiance_t.z}, b.counts.x, b.counts.y};
    });
    return Status::ok();
  }

 private:
  GpuPathTracer& tracer() const { return *session_->reference_tracer; }
  std::shared_ptr<GpuSession> session_;
  std::vector<gpu::GpuPathRay> gpu_rays_;
  std::vector<gpu::GpuPathBrief> briefs_;
};

}  // namespace

std::unique_ptr<ReferencePathDevice> make_gpu_reference_paths(std::shared_ptr<GpuSession> session,
                                                              bool cpu_device_too) {
  if (!session || !session->reference_tracer || !session->vk) return nullptr;
  if (!session->vk->device().is_gpu() && !cpu_device_too) return nullptr;
  return std::make_unique<GpuReferencePaths>(std::move(session));
}

}  // namespace gibake
