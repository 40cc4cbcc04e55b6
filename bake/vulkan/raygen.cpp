#include "bake/vulkan/raygen.h"

#include <algorithm>

#include "bake/vulkan/pipelines.h"
#include "kernels/ray_gen.h"

namespace gibake {

gpu::GpuRayGenProbe raygen_probe(const kernels::float3& o, uint64_t seed, uint32_t probe, uint32_t pass) {
  // The rotation is made here, as generate_probe_rays_from_set makes it: sin and cos stay on the CPU.
  const kernels::Rotation3 r = kernels::random_rotation(seed, probe, pass);
  gpu::GpuRayGenProbe g{};
  g.org = {o.x, o.y, o.z, 0.f};
  g.rot0 = {r.m[0], r.m[1], r.m[2], 0.f};
  g.rot1 = {r.m[3], r.m[4], r.m[5], 0.f};
  g.rot2 = {r.m[6], r.m[7], r.m[8], 0.f};
  g.key = {probe, pass, 0u, 0u};
  return g;
}

Status GpuRayGen::create(vk::Context& vk, std::unique_ptr<GpuRayGen>& out) {
  std::unique_ptr<GpuRayGen> g(new GpuRayGen(vk));
  GIBAKE_TRY(vk.create_pipeline(pipelines::raygen(), g->pipeline_));
  out = std::move(g);
  return Status::ok();
}

std::vector<uint32_t> lane_order(const float* set, uint32_t n, uint32_t block) {
  std::vector<uint32_t> order(std::max<uint32_t>(n, 1));
  for (uint32_t k = 0; k < order.size(); ++k) order[k] = k;
  if (block < 2 || n % block != 0) return order;
  std::vector<float> azimuth(n);
  for (uint32_t r = 0; r < n; ++r) azimuth[r] = std::atan2(set[r * 3 + 1], set[r * 3]);
  for (uint32_t first = 0; first < n; first += block)
    std::sort(order.begin() + first, order.begin() + first + block,
              [&](uint32_t a, uint32_t b) { return azimuth[a] != azimuth[b] ? azimuth[a] < azimuth[b] : a < b; });
  return order;
}

Status GpuRayGen::set_fibonacci(const float* set, uint32_t n, uint32_t block) {
  if (n == rays_per_probe_ && block == block_ && std::equal(set, set + size_t(n) * 3, set_.begin()))
    return Status::ok();
  const std::vector<uint32_t> order = lane_order(set, n, block);
  order_ = vk::Buffer();
  GIBAKE_TRY(vk_.create_buffer(order.size() * sizeof(uint32_t), order_, "lane order of a probe's rays"));
  GIBAKE_TRY(vk_.upload(order_, order.data(), order.size() * sizeof(uint32_t)));
  block_ = block;
  std::vector<gpu::vec4> v(std::max<uint32_t>(n, 1), gpu::vec4{0.f, 0.f, 0.f, 0.f});
  for (uint32_t i = 0; i < n; ++i) v[i] = {set[i * 3], set[i * 3 + 1], set[i * 3 + 2], 0.f};
  fib_ = vk::Buffer();
  GIBAKE_TRY(vk_.create_buffer(v.size() * sizeof(gpu::vec4), fib_, "spherical Fibonacci set"));
  GIBAKE_TRY(vk_.upload(fib_, v.data(), v.size() * sizeof(gpu::vec4)));
  set_.assign(set, set + size_t(n) * 3);
  rays_per_probe_ = n;
  return Status::ok();
}

Status GpuRayGen::reserve_probes(size_t probes) {
  if (probes <= probe_capacity_ && probes_.valid()) return Status::ok();
  probe_capacity_ = std::max<size_t>(probes, 1);
  probes_ = vk::Buffer();
  return vk_.create_buffer(probe_capacity_ * sizeof(gpu::GpuRayGenProbe), probes_, "ray generation probes");
}

Status GpuRayGen::set_probes(const std::vector<gpu::GpuRayGenProbe>& probes) {
  GIBAKE_TRY(reserve_probes(probes.size()));
  if (probes.empty()) return Status::ok();
  return vk_.upload(probes_, probes.data(), probes.size() * sizeof(gpu::GpuRayGenProbe));
}

Status GpuRayGen::record_probes(const std::vector<gpu::GpuRayGenProbe>& probes, vk::Recording& rec) {
  // Growing here would free the table under a chunk still in flight.
  if (probes.size() > probe_capacity_ || !probes_.valid())
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "ray generation table not reserved for the chunk");
  rec.upload(probes_, probes.data(), probes.size() * sizeof(gpu::GpuRayGenProbe));
  return Status::ok();
}

vk::Dispatch GpuRayGen::dispatch(const vk::Buffer& rays, uint32_t first, uint32_t n, uint64_t seed,
                                 bool geometry) const {
  const gpu::RayGenPush push{{n, rays_per_probe_, first, geometry ? 1u : 0u},
                             {uint32_t(seed), uint32_t(seed >> 32), 0u, 0u}};
  vk::Dispatch d;
  d.pipeline = &pipeline_;
  d.buffers = {&fib_, &probes_, &rays, &order_};
  d.push = vk::push_bytes(push);
  d.flat_groups = (n + 63) / 64;
  return d;
}

}  // namespace gibake
