// The path-traced gather (--gather path) on a Vulkan device: kernels/shaders/path.comp traces each
// probe ray as a whole path (the twin of trace_probe_paths: same random keys and streams, same
// shading, NEE with MIS, roulette) over a GpuTracer's BVH. The scene's shading data (vertices,
// materials, every texture with its mip chain, lights, emitters, sky) is packed and uploaded once.
// The probe rays are made on the device too (bake/vulkan/raygen.h) from one record per probe, and the
// kernel can write each ray's integration sample straight into the integration's device buffer.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bake/scene/emitters.h"
#include "bake/scene/sky.h"
#include "bake/scene/texture_lod.h"
#include "bake/trace/probe_rays.h"
#include "bake/vulkan/probe_field.h"
#include "bake/vulkan/probe_stats.h"
#include "bake/vulkan/raygen.h"
#include "bake/vulkan/texture_pool.h"
#include "bake/vulkan/traverse.h"
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
  // The path gather pairs each probe ray with a light sample from the probe (TraceStage::probe_lights,
  // bake/trace/path_gather.h): emitters and the sky map; off without either.
  bool probe_lights = false;
  // The scene's textures already on the device (the session's, made by the set-up from `lod`);
  // null or made from other mips: the tracer packs and uploads its own.
  const GpuTexturePool* textures = nullptr;
};

// One chunk of probes for the device: their ray-generation records (raygen_probe, in slot order)
// and, optionally, the buffer path.comp fills with each ray's integration sample (chunk ray order).
struct PathChunk {
  const std::vector<gpu::GpuRayGenProbe>* probes = nullptr;
  uint64_t seed = 0;
  const vk::Buffer* samples = nullptr;  // null: no samples written
  float max_distance = 0.f;             // the depth of misses, for the samples
  bool brief = false;                   // download GpuPathBriefs instead of GpuPathOuts
  // With brief, where the device has doubles: reduce the briefs to one GpuProbeStats per probe on
  // the device and download those instead (bake/vulkan/probe_stats.h).
  bool stats = false;
  // With stats, --target-error's passes: each probe's state over its passes before (slot order),
  // uploaded for the statistics kernel to continue; null: every probe starts fresh.
  const std::vector<gpu::GpuProbeStats>* resume = nullptr;
};

// One output per ray of a chunk, in ray order: `outs`, or `briefs` when the chunk asked for them;
// or, when the chunk asked for statistics and the device reduced them, one `stats` per probe.
struct PathResult {
  std::vector<gpu::GpuPathOut> outs;
  std::vector<gpu::GpuPathBrief> briefs;
  std::vector<gpu::GpuProbeStats> stats;
  // With the probe's emitter samples, each ray's paired sample, alongside `outs` or `briefs`.
  std::vector<kernels::RaySample> lights;
};

// Device time of a trace, per kernel (timestamp queries).
struct PathTimes {
  double path = 0.0, raygen = 0.0, stats = 0.0;
};

struct PathRecorded;  // bake/vulkan/path_pipeline.h

// Device bytes a ray of a path-kernel batch takes at most: its GpuPathRay, GpuPathOut, GpuPathBrief
// and paired emitter sample (the brief route makes no GpuPathOut: reserve_batch). The batch size and
// the path gather's memory check count them all.
constexpr uint64_t kPathBatchBytesPerRay =
    sizeof(gpu::GpuPathRay) + sizeof(gpu::GpuPathOut) + sizeof(gpu::GpuPathBrief) + sizeof(gpu::GpuRaySample);
// Rays one path-kernel dispatch traces at most on `device`. Large on a GPU: each dispatch ends on
// its longest paths with most of the device idle, and between dispatches the queue drains, so
// larger batches keep a GPU busy for a larger share of the trace (docs/BENCHMARKS.md has the
// sweep). 2^23 where 1/32 of the device's memory holds it (fewer otherwise); 2^19 on a CPU device (lavapipe),
// where dispatches cost nothing to start and memory is the host's.
uint32_t path_batch_rays(const vk::DeviceInfo& device, uint64_t device_memory);

class GpuPathTracer {
 public:
  ~GpuPathTracer();
  GpuPathTracer(const GpuPathTracer&) = delete;
  GpuPathTracer& operator=(const GpuPathTracer&) = delete;

  // Packs and uploads the shading data; fails with the bytes needed when it does not fit.
  // `batch_rays`: rays a dispatch traces at most; 0: path_batch_rays. The batch buffers are made
  // by reserve_chunks, no larger than a chunk needs.
  static Status create(GpuTracer& bvh, const GpuPathSetup& setup, std::unique_ptr<GpuPathTracer>& out,
                       uint32_t batch_rays = 0);
  uint32_t max_batch_rays() const { return max_batch_; }
  // The unrotated spherical Fibonacci set (xyz triples) every probe's rays rotate; uploaded once.
  Status set_fibonacci(const float* set, uint32_t rays_per_probe);
  uint64_t device_bytes() const { return device_bytes_; }
  // Whether each ray is paired with an emitter sample: a chunk's integration samples are then the
  // rays of a probe followed by their emitter samples (twice as many).
  bool probe_lights() const { return params_.sky_map.w != 0u; }
  // Whether chunks can reduce to per-probe statistics on the device (PathChunk::stats).
  bool device_stats() const { return stats_ != nullptr; }
  // Seconds create() spent packing the shading data, uploading it, and creating the pipelines.
  const double* setup_seconds() const { return setup_seconds_; }
  // Whether a trace set up with `other` may use this tracer as made: the same scene, textures,
  // emitters, sky, lights and path settings, so that its shading data and parameters are the bytes
  // create() would make again (a later volume of the same bake).
  bool serves(const GpuPathSetup& other) const;
  // The asynchronous route (bake/vulkan/path_pipeline.cpp defines these): room for chunks of up to
  // `probes` probes, made before any chunk is in flight; a chunk's steps (ray generation on the
  // device, rays_per_probe per probe, probe after probe, the path kernel, the statistics) recorded
  // into `rec`; its outputs, one per ray in that order (or one per probe), read back once `rec` has run.
  Status reserve_chunks(size_t probes, bool full_outputs = true);
  Status record(const PathChunk& chunk, vk::Recording& rec, PathRecorded& out);
  void collect(const vk::Recording& rec, const PathRecorded& recorded, PathResult& out, PathTimes* times) const;

  // The reconstruction check's reference paths (path.comp mode 2, reference_sums.comp;
  // bake/vulkan/reference_paths.cpp): `n` points' `rays` paths each, made and traced on the device
  // with these path settings instead of the bake's, summed per point there, waited for. At most
  // max_batch_rays paths.
  struct ReferenceParams {
    uint32_t rays = 0, strata = 0;  // paths per point; m (the first m x m paths are stratified)
    int bounces = 4, roulette_depth = 3;
    float cone_spread = 0.f, shadow_bias = 1e-4f;
  };
  Status trace_reference(const gpu::GpuReferencePoint* points, uint32_t n, const ReferenceParams& params,
                         gpu::GpuReferenceSums* out);
  // From now on trace_reference also ends each path at its first hit in `field`'s probes
  // (path_probe_field.comp, probe_field_ended.comp; GpuReferenceSums::ended): uploads the packed
  // probes and makes the kernels. Fails, keeping nothing, where the device cannot hold the probes
  // or bind a kernel's buffers. Null: no longer, and the probes' buffers are freed.
  Status set_probe_field(const PackedProbeField* field);
  // Hands the ray batches (sized for the trace: gigabytes on a GPU) to `take` and keeps the
  // shading data and pipelines; a later use makes batches its own size.
  struct Batches {
    vk::Buffer rays, outs, briefs, light_out;
  };
  void release_batches(std::unique_ptr<Batches>& take);
  // What the shading data was packed from: the lights, and the sky's constant, scale, size and map.
  bool lit_by(const std::vector<kernels::ShadeLight>& lights, const Sky& sky) const;

 private:
  explicit GpuPathTracer(GpuTracer& bvh) : bvh_(bvh) {}
  // The path kernel over rays [first, first + n) of a chunk.
  vk::Dispatch path_dispatch(const PathChunk& c, uint32_t first, uint32_t n) const;
  // `order`: raygen's lane order (null: a placeholder, for rays in their own order).
  vk::Dispatch path_dispatch(const gpu::PathPush& push, const vk::Buffer* samples, const vk::Buffer* order,
                             uint32_t n) const;
  GpuTracer& bvh_;
  // Grows the batch buffers to hold `rays` (at most max_batch_), before any chunk is in flight;
  // the per-ray outputs (GpuPathOut, 80 of a ray's 192 bytes) only with `full_outputs`, since the
  // brief route never writes them (no_samples_ is bound in their place).
  Status reserve_batch(uint64_t rays, bool full_outputs);
  // Device bytes of the batch buffers as made.
  uint64_t batch_bytes() const;
  uint32_t max_batch_ = 0, batch_ = 0, outs_batch_ = 0;
  uint64_t device_bytes_ = 0;
  double setup_seconds_[3] = {0.0, 0.0, 0.0};
  GpuPathSetup setup_;  // as create() was given it (serves)
  gpu::GpuPathParams params_{};
  std::vector<kernels::ShadeLight> host_lights_;  // lit_by's
  uint64_t sky_map_hash_ = 0;                     // XXH3 of the sky map's texels (0: none)
  std::unique_ptr<GpuRayGen> raygen_;
  std::unique_ptr<GpuProbeStatsReducer> stats_;  // null: no shaderFloat64
  std::unique_ptr<GpuTexturePool> own_textures_;  // when the setup handed none
  const GpuTexturePool* textures_ = nullptr;
  vk::Buffer verts_, shade_tris_, shade_mats_, lights_, emit_cdf_, emit_tris_, sky_, params_buf_, rays_, outs_, briefs_,
      no_samples_, light_out_, sky_cdf_;
  vk::Pipeline path_;
  // The reference paths' points and sums, made by their first use.
  vk::Buffer ref_points_, ref_sums_, ref_briefs_;
  vk::Pipeline ref_sums_pipeline_;
  // set_probe_field's: the packed probes (probe_field.glsl's four buffers), each path's first hit
  // (three vec4s, then its ended radiance in the first), the kernels that write and light them.
  vk::Buffer field_[4], ref_first_hits_;
  vk::Pipeline path_field_, ended_pipeline_;
  bool has_field_ = false;
};

// A kernels::HitRecord from a GPU path output, with the counters trace_probe_paths keeps.
kernels::HitRecord path_record(const gpu::GpuPathOut& o, TraceCounters& counters);
// The same from a brief: direction, normal and albedo stay zero (nothing reads them when the
// samples stay on the device and no bounce pass re-shades the hits).
kernels::HitRecord path_record(const gpu::GpuPathBrief& b, TraceCounters& counters);

struct PathRays {
  uint32_t rays_per_probe = 0;
  const float* fibonacci = nullptr;  // the unrotated set of rays_per_probe directions
  uint64_t seed = 0;                 // keys rng_hash(seed, probe, pass, ray)
  // Writes the ray-generation record (raygen_probe) of each of `probes`, in order.
  std::function<void(const std::vector<int32_t>& probes, gpu::GpuRayGenProbe* out)> fill;
  float max_distance = 0.f;  // the depth of misses, for the integration samples
  // With an integrator (the samples stay on the device): download GpuPathBriefs (32 bytes a ray)
  // instead of GpuPathOuts (80).
  bool brief = false;
  bool stats = false;  // with brief: per-probe statistics instead, where the device can (PathChunk::stats)
  // With stats and an integrator, --target-error's passes on the device: each probe's statistics
  // over its passes before (indexed by probe; counts.x rays so far) continued there, and its
  // integrals accumulated in its slot (the probe's index less slot_base) instead of read back.
  const std::vector<gpu::GpuProbeStats>* resume = nullptr;
  int32_t slot_base = 0;  // the first probe of the group of passes (DdgiDevice::pass_group_probes)
};

// One probe's rays as the CPU would make them: origin, directions (xyz triples), keys of (seed,
// probe, pass, ray). With generate_probe_rays_from_set, the CPU twin of raygen.comp.
void make_path_rays(const kernels::float3& origin, const float* dirs, uint32_t count, uint64_t seed, uint32_t probe,
                    uint32_t pass, gpu::GpuPathRay* out);

}  // namespace gibake
