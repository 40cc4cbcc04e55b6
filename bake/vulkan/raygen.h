// Probe rays of the path gather made on a Vulkan device (kernels/shaders/raygen.comp), so no
// per-ray data crosses the bus on the way in: per chunk, one small record per probe (origin, the
// rotation of kernels::random_rotation, probe and pass) and, once per bake, the unrotated spherical
// Fibonacci set. The CPU twin is kernels::generate_probe_rays_from_set + make_path_rays: keys and
// origins identical, directions within 1e-6 (tests/vulkan/gpu_raygen_test.cpp).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "kernels/shaders/gpu_types.h"
#include "kernels/vec.h"
#include "kernels/vulkan/context.h"

namespace gibake {

// The record raygen.comp reads for probe `probe` in pass (batch) `pass`.
gpu::GpuRayGenProbe raygen_probe(const kernels::float3& origin, uint64_t seed, uint32_t probe, uint32_t pass);

// The order in which a subgroup's lanes take a probe's n rays: each block of `block` consecutive rays
// of the spherical Fibonacci set (a band of z, its points spread around it by the golden angle)
// sorted by azimuth, so that neighbouring lanes trace neighbouring directions (and, from one probe,
// hit neighbouring surfaces) instead of directions 137.5 degrees apart. Blocks that do not divide n,
// or a block of 1: the identity. Entry k: the ray traced at lane position k.
std::vector<uint32_t> lane_order(const float* set, uint32_t n, uint32_t block);

class GpuRayGen {
 public:
  static Status create(vk::Context& vk, std::unique_ptr<GpuRayGen>& out);

  // Uploads the unrotated n-point set (xyz triples) unless it is the one already there, and the
  // lane order of each probe's rays (lane_order below) for blocks of `block` rays (1: ray order).
  Status set_fibonacci(const float* set, uint32_t n, uint32_t block = 1);
  // Uploads one chunk's probe records (slot order), growing the table when needed.
  Status set_probes(const std::vector<gpu::GpuRayGenProbe>& probes);
  // The asynchronous route (bake/vulkan/path_pipeline.h): room for `probes` records, made before any
  // chunk is in flight; then each chunk's records uploaded as a step of its recording.
  Status reserve_probes(size_t probes);
  Status record_probes(const std::vector<gpu::GpuRayGenProbe>& probes, vk::Recording& rec);
  // The dispatch writing rays [first, first + n) of the chunk (probe slot-major, the set's size
  // per probe, keys of `seed`) to rays[0 .. n). `geometry`: GpuRays without keys (relocation).
  vk::Dispatch dispatch(const vk::Buffer& rays, uint32_t first, uint32_t n, uint64_t seed, bool geometry = false) const;
  uint32_t rays_per_probe() const { return rays_per_probe_; }
  // Per lane position k of a probe's rays, the ray it traces (path.comp writes the ray's results
  // at the ray's own position); the identity unless set_fibonacci was given a block.
  const vk::Buffer& order() const { return order_; }

 private:
  explicit GpuRayGen(vk::Context& vk) : vk_(vk) {}
  vk::Context& vk_;
  uint32_t rays_per_probe_ = 0;
  std::vector<float> set_;  // the uploaded set, to skip uploading it again
  uint32_t block_ = 0;
  size_t probe_capacity_ = 0;
  vk::Buffer fib_, probes_, order_;
  vk::Pipeline pipeline_;
};

}  // namespace gibake
