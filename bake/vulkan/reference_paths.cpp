#include "bake/vulkan/reference_paths.h"

#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bake/vulkan/path.h"
#include "bake/vulkan/pipelines.h"

namespace gibake {

namespace {

constexpr uint64_t kFirstHitBytes = 48;  // path_kernel.glsl write_first_hit: three vec4s a path

}  // namespace

Status GpuPathTracer::trace_reference(const gpu::GpuReferencePoint* points, uint32_t n, const ReferenceParams& p,
                                      gpu::GpuReferenceSums* out) {
  const uint64_t paths = uint64_t(n) * p.rays;
  if (n == 0 || p.rays == 0) return Status::ok();
  if (paths > max_batch_)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "more reference paths than one batch holds");
  vk::Context& vk = bvh_.vk_;
  if (!ref_sums_pipeline_.impl()) GIBAKE_TRY(vk.create_pipeline(pipelines::reference_sums(), ref_sums_pipeline_));
  // Buffers of their own, the check's size (the trace's batches are gone by now: release_batches).
  if (ref_points_.size() < uint64_t(n) * sizeof(gpu::GpuReferencePoint)) {
    GIBAKE_TRY(vk.create_buffer(uint64_t(n) * sizeof(gpu::GpuReferencePoint), ref_points_, "reference points"));
    GIBAKE_TRY(vk.create_buffer(uint64_t(n) * sizeof(gpu::GpuReferenceSums), ref_sums_, "reference sums"));
  }
  if (ref_briefs_.size() < paths * sizeof(gpu::GpuPathBrief))
    GIBAKE_TRY(vk.create_buffer(paths * sizeof(gpu::GpuPathBrief), ref_briefs_, "reference path briefs"));
  gpu::GpuPathParams params = params_;
  params.counts.x = uint32_t(paths);
  params.flags.x = 0u;  // trace_radiance evaluates every light at each vertex
  params.flags.y = uint32_t(std::max(0, p.bounces));
  params.flags.z = uint32_t(std::max(0, p.roulette_depth));
  params.sky_map.z = 2u;  // mode 2: the reference paths
  // Each path paired with an emitter sample at its point where the scene has emitters
  // (trace_surface_radiance); the sky is left to the paths.
  params.sky_map.w = params.counts.w > 0u ? 1u : 0u;
  params.misc.x = p.cone_spread;
  params.misc.y = p.shadow_bias;
  params.misc.w = 0.f;  // no share of the light samples for the sky map
  // The points in the ray batch's place, no integration samples.
  const gpu::PathPush push{{0u, p.strata, 1u, p.rays}, {0.f, 0.f, 0.f, 0.f}};
  vk::Dispatch trace = path_dispatch(push, nullptr, nullptr, uint32_t(paths));
  trace.buffers[18] = &ref_points_;
  trace.buffers[19] = &no_samples_;  // no GpuPathOuts, no emitter samples: never written in mode 2
  trace.buffers[21] = &ref_briefs_;
  trace.buffers[22] = &no_samples_;
  std::vector<vk::Dispatch> steps = {trace};
  if (has_field_) {  // the paths' first hits (binding 25), then lit by the probes
    steps[0].pipeline = &path_field_;
    steps[0].buffers.push_back(&ref_first_hits_);
    vk::Dispatch ended;
    ended.pipeline = &ended_pipeline_;
    ended.buffers = {&ref_first_hits_};
    for (const vk::Buffer& b : field_) ended.buffers.push_back(&b);
    ended.push = vk::push_bytes(gpu::uvec4{uint32_t(paths), 0u, 0u, 0u});
    ended.flat_groups = uint32_t((paths + 63) / 64);
    steps.push_back(std::move(ended));
  }
  for (uint32_t w = 0; w == 0 || w < p.rays; w += GPU_RAY_WINDOW) {  // a window of each point's paths
    vk::Dispatch sums;
    sums.pipeline = &ref_sums_pipeline_;
    sums.buffers = {&ref_briefs_, &ref_sums_, has_field_ ? &ref_first_hits_ : &ref_briefs_};
    sums.push =
        vk::push_bytes(gpu::ReferenceSumsPush{{n, p.rays, w, GPU_RAY_WINDOW}, {has_field_ ? 1u : 0u, 0u, 0u, 0u}});
    sums.flat_groups = (n + 63) / 64;
    steps.push_back(std::move(sums));
  }
  // Through the context's own staging and command buffer: a fresh recording's pools and pinned
  // staging would cost more than the paths themselves.
  GIBAKE_TRY(vk.upload(ref_points_, points, uint64_t(n) * sizeof(gpu::GpuReferencePoint)));
  GIBAKE_TRY(vk.upload(params_buf_, &params, sizeof(params)));
  GIBAKE_TRY(vk.run(steps));
  GIBAKE_TRY(vk.download(ref_sums_, out, uint64_t(n) * sizeof(gpu::GpuReferenceSums)));
  return Status::ok();
}

Status GpuPathTracer::set_probe_field(const PackedProbeField* field) {
  vk::Context& vk = bvh_.vk_;
  has_field_ = false;
  for (vk::Buffer& b : field_) b = vk::Buffer{};
  ref_first_hits_ = vk::Buffer{};
  if (!field) return Status::ok();
  if (!path_field_.impl()) GIBAKE_TRY(vk.create_pipeline(pipelines::path_probe_field(), path_field_));
  if (!ended_pipeline_.impl()) GIBAKE_TRY(vk.create_pipeline(pipelines::probe_field_ended(), ended_pipeline_));
  const void* data[4] = {field->words.data(), field->vec4s.data(), field->floats.data(), field->volumes.data()};
  const uint64_t bytes[4] = {field->words.size() * sizeof(uint32_t), field->vec4s.size() * sizeof(float),
                             field->floats.size() * sizeof(float),
                             field->volumes.size() * sizeof(loader::GlslDdgiVolume)};
  static const char* const kNames[4] = {"probe field words", "probe field vec4s", "probe field floats",
                                        "probe field volumes"};
  // Made aside and kept only when all are made: a failure keeps nothing.
  vk::Buffer made[4], first_hits;
  for (int i = 0; i < 4; ++i) {
    GIBAKE_TRY(vk.create_buffer(std::max<uint64_t>(bytes[i], 16), made[i], kNames[i]));  // an empty one still binds
    if (bytes[i]) GIBAKE_TRY(vk.upload(made[i], data[i], bytes[i]));
  }
  // Room for the largest trace's first hits (trace_reference takes at most max_batch_ paths), so
  // that a device short of it refuses the field here (the CPU then ends the paths) rather than
  // failing the trace.
  GIBAKE_TRY(vk.create_buffer(uint64_t(max_batch_) * kFirstHitBytes, first_hits, "reference paths' first hits"));
  for (int i = 0; i < 4; ++i) field_[i] = std::move(made[i]);
  ref_first_hits_ = std::move(first_hits);
  has_field_ = true;
  return Status::ok();
}

void GpuPathTracer::release_batches(std::unique_ptr<Batches>& take) {
  take = std::make_unique<Batches>();
  take->rays = std::move(rays_);
  take->outs = std::move(outs_);
  take->briefs = std::move(briefs_);
  take->light_out = std::move(light_out_);
  device_bytes_ -= batch_bytes();
  batch_ = outs_batch_ = 0;
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
  uint64_t max_paths() const override { return tracer().max_batch_rays(); }
  std::string name() const override { return session_->vk->device().name; }

  Status trace(const std::vector<ReferencePoint>& points, const ReferencePathParams& p,
               std::vector<ReferencePointSums>& out) override {
    GpuPathTracer::ReferenceParams params;
    params.rays = p.rays;
    params.strata = uint32_t(std::sqrt(double(p.rays)));  // reconstruction_check.cpp's m
    params.bounces = p.bounces;
    params.roulette_depth = p.roulette_depth;
    params.cone_spread = p.cone_spread;
    params.shadow_bias = p.shadow_bias;
    const size_t n = points.size();
    std::vector<gpu::GpuReferencePoint> gpu_points(n);
    for (size_t i = 0; i < n; ++i) {
      const ReferencePoint& q = points[i];
      gpu_points[i] = {{q.origin.x, q.origin.y, q.origin.z, 0.f},
                       {q.n.x, q.n.y, q.n.z, 0.f},
                       {q.ng.x, q.ng.y, q.ng.z, 0.f},
                       {uint32_t(q.key), uint32_t(q.key >> 32), uint32_t(p.salt), uint32_t(p.salt >> 32)}};
    }
    std::vector<gpu::GpuReferenceSums> sums(n);
    GIBAKE_TRY(tracer().trace_reference(gpu_points.data(), uint32_t(n), params, sums.data()));
    out.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const gpu::GpuReferenceSums& g = sums[i];
      ReferencePointSums& o = out[i];
      o.sum = kernels::float3{g.sum.x, g.sum.y, g.sum.z};
      o.half_lum[0] = g.sum.w;
      o.half_lum[1] = g.half_lum.x;
      o.half_count[0] = g.counts.x;
      o.half_count[1] = g.counts.y;
      o.shadow_rays = g.counts.z;
      o.bounce_rays = g.counts.w;
      o.traced = g.traced.x;
      o.ended_sum = kernels::float3{g.ended.x, g.ended.y, g.ended.z};
      o.ended_half_lum[0] = g.ended.w;
      o.ended_half_lum[1] = g.half_lum.y;
    }
    return Status::ok();
  }

  Status end_paths_in(const loader::BakeFile* file) override {
    if (!file) return tracer().set_probe_field(nullptr);
    // The packed field holds every probe of the grid; a sparse volume's paths end on the CPU.
    for (const loader::DdgiVolume& v : file->ddgi_volumes())
      if (v.sparse()) return Status::invalid("", "probe field", "a sparse volume: paths end on the CPU");
    const PackedProbeField packed = pack_probe_field(*file);
    return tracer().set_probe_field(&packed);
  }

 private:
  GpuPathTracer& tracer() const { return *session_->reference_tracer; }
  std::shared_ptr<GpuSession> session_;
};

}  // namespace

std::unique_ptr<ReferencePathDevice> make_gpu_reference_paths(std::shared_ptr<GpuSession> session,
                                                              bool cpu_device_too) {
  if (!session || !session->reference_tracer || !session->vk) return nullptr;
  if (!session->vk->device().is_gpu() && !cpu_device_too) return nullptr;
  return std::make_unique<GpuReferencePaths>(std::move(session));
}

}  // namespace gibake
