// Relocation statistics on a Vulkan device: per chunk of probes, raygen.comp makes the geometry
// rays (one record per probe, the Fibonacci set uploaded once), traverse.comp traces them and
// reloc_sums.comp reduces each probe's hits to relocation_sums, all in one submission; only the
// probe records go up and 32 bytes a probe come back. The CPU applies the move
// (apply_relocation), as it does after the per-ray path (bake/vulkan/geometry.h), which stays for
// ray capture and devices without doubles.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bake/ddgi/relocate.h"
#include "bake/vulkan/raygen.h"
#include "bake/vulkan/traverse.h"
#include "io/scene.h"

namespace gibake {

// Per Scene triangle: its counter-clockwise normal as geometry_record computes it and whether its
// material is double sided (what decides front against back on the device).
std::vector<gpu::GpuRelocTri> reloc_triangles(const Scene& scene);

class GpuRelocation {
 public:
  // `fibonacci`: the unrotated set of `rays` directions. Sets `out` to null (and returns ok) when
  // the device has no shaderFloat64: the caller keeps the per-ray path.
  static Status create(GpuTracer& tracer, const Scene& scene, const float* fibonacci, uint32_t rays,
                       std::unique_ptr<GpuRelocation>& out, uint64_t chunk_rays = uint64_t(1) << 20);

  // Whether this object traces what create(tracer, scene, fibonacci, rays) would make: the same
  // tracer, scene and direction set (a later volume of a bake reuses it instead of building its
  // pipelines, triangles and buffers again).
  bool serves(const GpuTracer& tracer, const Scene& scene, const float* fibonacci, uint32_t rays) const;

  // One pass: sums[i] for probes[i], rays from origin(probe) rotated by random_rotation(seed,
  // probe, pass), as generate_probe_rays_from_set makes them.
  Status sums(const std::vector<int32_t>& probes, uint64_t seed, uint32_t pass,
              const std::function<kernels::float3(int32_t)>& origin, float threshold, std::vector<RelocationSums>& out);

 private:
  GpuRelocation(GpuTracer& tracer) : tracer_(tracer) {}
  std::vector<vk::Dispatch> sums_dispatches(uint32_t probes, float threshold);  // one per window of rays

  GpuTracer& tracer_;
  const Scene* scene_ = nullptr;
  std::vector<float> fibonacci_;  // what create uploaded: serves compares it
  std::unique_ptr<GpuRayGen> raygen_;
  uint32_t rays_ = 0;
  size_t chunk_probes_ = 1;
  vk::Buffer tris_, rays_buf_, hits_, sums_;
  vk::Pipeline pipeline_;
  vk::Recording recordings_[2];  // two chunks in flight; kept, with their staging memory, across passes
};

}  // namespace gibake
