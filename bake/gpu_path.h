// The path-traced gather (--gather path) on a Vulkan device: kernels/shaders/path.comp traces each
// probe ray as a whole path (the twin of trace_probe_paths: same random keys and streams, same
// shading, NEE with MIS, roulette) over a GpuTracer's BVH. The scene's shading data (vertices,
// materials, every texture with its mip chain, lights, emitters, sky) is packed and uploaded once.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bake/emitters.h"
#include "bake/gpu_trace.h"
#include "bake/sky.h"
#include "bake/texture_lod.h"
#include "bake/trace.h"
#include "io/scene.h"
#include "kernels/shade.h"

namespace gibake {

struct GpuPathSetup {
  const Scene* scene = nullptr;
  const TextureLod* lod = nullptr;
  const EmitterTable* emitters = nullptr;
  const std::vector<kernels::ShadeLight>* lights = nullptr;
  const Sky* sky = nullptr;
  bool random_light = false;
  int bounces = 4;
  int roulette_depth = 3;
  float cone_spread = 0.f;
  float shadow_bias = 1e-4f;
  // --gather probes: each probe ray's hit only (shading normal, albedo, emission + direct light:
  // trace_probe_rays' records); the bounce passes then run on the CPU.
  bool probe_feedback = false;
};

class GpuPathTracer {
 public:
  ~GpuPathTracer();
  GpuPathTracer(const GpuPathTracer&) = delete;
  GpuPathTracer& operator=(const GpuPathTracer&) = delete;

  // Packs and uploads the shading data; fails with the bytes needed when it does not fit.
  static Status create(GpuTracer& bvh, const GpuPathSetup& setup, std::unique_ptr<GpuPathTracer>& out,
                       uint32_t batch_rays = 1u << 19);
  Status trace(const std::vector<gpu::GpuPathRay>& rays, std::vector<gpu::GpuPathOut>& out,
               double* gpu_seconds = nullptr);
  uint64_t device_bytes() const { return device_bytes_; }

 private:
  explicit GpuPathTracer(GpuTracer& bvh) : bvh_(bvh) {}
  GpuTracer& bvh_;
  uint32_t batch_ = 0;
  uint64_t device_bytes_ = 0;
  gpu::GpuPathParams params_{};
  vk::Buffer verts_, shade_tris_, shade_mats_, shade_tex_, levels_, pool_, srgb_, lights_, emit_cdf_, emit_tris_, sky_,
      params_buf_, rays_, outs_;
  vk::Pipeline path_;
};

// A kernels::HitRecord from a GPU path output, with the counters trace_probe_paths keeps.
kernels::HitRecord path_record(const gpu::GpuPathOut& o, TraceCounters& counters);

struct PathRays {
  uint32_t rays_per_probe = 0;
  // Writes the rays of `probes` (rays_per_probe each, in order; keys rng_hash(seed, probe, pass,
  // ray)). The caller fills them in parallel.
  std::function<void(const std::vector<int32_t>& probes, gpu::GpuPathRay* rays)> fill;
  // Called once per chunk with its probes and their outputs (rays_per_probe per probe, in order);
  // an error (from device work it starts) ends the trace.
  std::function<Status(const std::vector<int32_t>& probes, const gpu::GpuPathOut* outs)> done;
  double* gpu_seconds = nullptr;   // optional: adds the path kernels' device time
  double* call_seconds = nullptr;  // optional: adds the wall time of the traces (transfers included)
  double* host_seconds = nullptr;  // optional: adds the wall time of fill and done (host work)
};

// One probe's rays: origin, directions (xyz triples), keys of (seed, probe, pass, ray).
void make_path_rays(const kernels::float3& origin, const float* dirs, uint32_t count, uint64_t seed, uint32_t probe,
                    uint32_t pass, gpu::GpuPathRay* out);

// Traces every probe's rays in chunks of about `chunk_rays` rays.
Status trace_paths_gpu(GpuPathTracer& tracer, const std::vector<int32_t>& probes, const PathRays& p,
                       uint64_t chunk_rays = uint64_t(1) << 21);

}  // namespace gibake
