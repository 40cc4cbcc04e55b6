#include "bake/vulkan/integrate.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "io/results/ddgi_result.h"
#include "kernels/sh.h"
#include "kernels/shaders/gpu_types.h"
#include "kernels/shaders/integrate_spv.h"

namespace gibake {
namespace {

static_assert(sizeof(gpu::GpuRaySample) == sizeof(kernels::RaySample), "GpuRaySample mirrors RaySample");
static_assert(kIrradianceTexels * kIrradianceTexels == GPU_IRRADIANCE_TEXELS, "irradiance tile");
static_assert(kDepthTexels * kDepthTexels == GPU_DEPTH_TEXELS && GPU_DEPTH_TEXELS == GPU_INTEGRATE_GROUP,
              "one invocation per depth texel");

constexpr size_t kIrrValues = GPU_IRRADIANCE_TEXELS * 3, kDepthValues = GPU_DEPTH_TEXELS * 2;

// xyz triples as vec4s (w unused): the very floats the CPU tables hold.
std::vector<gpu::vec4> as_vec4(const std::vector<float>& xyz) {
  std::vector<gpu::vec4> v(xyz.size() / 3);
  for (size_t i = 0; i < v.size(); ++i) v[i] = {xyz[i * 3], xyz[i * 3 + 1], xyz[i * 3 + 2], 0.f};
  return v;
}

}  // namespace

GpuIntegrator::~GpuIntegrator() = default;

Status GpuIntegrator::create(vk::Context& vk, int sh_order, std::unique_ptr<GpuIntegrator>& out, uint64_t batch_samples,
                             uint32_t batch_probes) {
  std::unique_ptr<GpuIntegrator> g(new GpuIntegrator(vk));
  g->coefs_ = kernels::sh_coefficient_count(sh_order);
  // The CPU's own tables, so texel directions and the cutoff are bit-identical.
  const kernels::DepthConeTable cone = kernels::build_depth_cone_table(kDepthTexels);
  g->cos_cutoff_ = cone.cos_cutoff;
  const std::vector<gpu::vec4> irr = as_vec4(kernels::oct_tile_directions(kIrradianceTexels));
  const std::vector<gpu::vec4> dep = as_vec4(cone.directions);
  g->batch_samples_ = std::max<uint64_t>(1, batch_samples);
  g->batch_probes_ = std::clamp<uint32_t>(batch_probes, 1, 65535);  // one workgroup per probe, groups.x
  const uint64_t np = g->batch_probes_;
  GIBAKE_TRY(vk.create_buffer(irr.size() * sizeof(gpu::vec4), g->irr_dirs_, "irradiance texel directions"));
  GIBAKE_TRY(vk.upload(g->irr_dirs_, irr.data(), irr.size() * sizeof(gpu::vec4)));
  GIBAKE_TRY(vk.create_buffer(dep.size() * sizeof(gpu::vec4), g->depth_dirs_, "depth texel directions"));
  GIBAKE_TRY(vk.upload(g->depth_dirs_, dep.data(), dep.size() * sizeof(gpu::vec4)));
  GIBAKE_TRY(vk.create_buffer(np * sizeof(gpu::GpuIntegrateProbe), g->probes_, "integration probe table"));
  GIBAKE_TRY(vk.create_buffer(np * g->coefs_ * 3 * 4, g->sh_, "integration SH"));
  GIBAKE_TRY(vk.create_buffer(np * kIrrValues * 4, g->irr_, "integration irradiance texels"));
  GIBAKE_TRY(vk.create_buffer(np * kDepthValues * 4, g->depth_, "integration depth moments"));
  GIBAKE_TRY(g->ensure_samples(g->batch_samples_));
  GIBAKE_TRY(vk.create_pipeline(shaders::integrate_spv, sizeof(shaders::integrate_spv) / 4, 7,
                                sizeof(gpu::IntegratePush), g->pipeline_, "integrate"));
  out = std::move(g);
  return Status::ok();
}

Status GpuIntegrator::ensure_samples(uint64_t count) {
  if (count <= sample_capacity_) return Status::ok();
  samples_ = vk::Buffer();
  GIBAKE_TRY(vk_.create_buffer(count * sizeof(gpu::GpuRaySample), samples_, "integration ray samples"));
  sample_capacity_ = count;
  return Status::ok();
}

Status GpuIntegrator::integrate(const kernels::RaySample* samples, const std::vector<uint32_t>& counts,
                                GpuIntegrateResult& out, bool paired) {
  paired_ = paired;
  return integrate_batches(samples, counts, out);
}

Status GpuIntegrator::reserve_samples(uint64_t count, vk::Buffer*& sample_buffer) {
  GIBAKE_TRY(ensure_samples(std::max<uint64_t>(1, count)));
  sample_buffer = &samples_;
  return Status::ok();
}

Status GpuIntegrator::integrate_resident(const std::vector<uint32_t>& counts, GpuIntegrateResult& out, bool paired) {
  paired_ = paired;
  uint64_t total = 0;
  for (uint32_t c : counts) total += uint64_t(c) * (paired ? 2 : 1);
  if (total > sample_capacity_)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         "integration of " + std::to_string(total) + " resident samples in a buffer of " +
                             std::to_string(sample_capacity_));
  return integrate_batches(nullptr, counts, out);
}

Status GpuIntegrator::integrate_batches(const kernels::RaySample* samples, const std::vector<uint32_t>& counts,
                                        GpuIntegrateResult& out) {
  const size_t n = counts.size();
  out.sh.assign(n * coefs_ * 3, 0.f);
  out.irradiance.assign(n * kIrrValues, 0.f);
  out.depth.assign(n * kDepthValues, 0.f);
  // Greedy batches: as many whole probes as fit the probe limit and, when samples are uploaded,
  // the sample limit (at least one probe).
  const uint64_t limit = samples ? batch_samples_ : ~uint64_t(0);
  uint64_t first_sample = 0;
  for (size_t first = 0; first < n;) {
    size_t count = 0;
    uint64_t batch = 0;
    const uint64_t per_ray = paired_ ? 2 : 1;  // samples per ray: with its paired emitter sample, 2
    while (first + count < n && count < batch_probes_ &&
           (count == 0 || batch + counts[first + count] * per_ray <= limit))
      batch += counts[first + count++] * per_ray;
    GIBAKE_TRY(dispatch(samples, counts, first, count, first_sample, batch, out));
    first += count;
    first_sample += batch;
  }
  return Status::ok();
}

std::vector<gpu::GpuIntegrateProbe> GpuIntegrator::probe_table(const uint32_t* counts, size_t n, uint32_t first_sample,
                                                               bool paired) {
  std::vector<gpu::GpuIntegrateProbe> table(n);
  uint32_t at = first_sample;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t c = counts[i];
    // The CPU's norm: 4pi/n in double, rounded to float once (n rays, whether or not their
    // emitter samples follow); the depth moments from the rays only.
    const float norm = c > 0 ? static_cast<float>(4.0 * 3.14159265358979323846 / c) : 0.f;
    uint32_t bits;
    std::memcpy(&bits, &norm, 4);
    const uint32_t total = paired ? 2 * c : c;
    table[i].range = {at, total, bits, c};
    at += total;
  }
  return table;
}

vk::Dispatch GpuIntegrator::integrate_dispatch(uint32_t probes) {
  const gpu::IntegratePush push{{probes, uint32_t(coefs_), 0u, 0u}, {cos_cutoff_, 0.f, 0.f, 0.f}};
  vk::Dispatch d;
  d.pipeline = &pipeline_;
  d.buffers = {&samples_, &probes_, &irr_dirs_, &depth_dirs_, &sh_, &irr_, &depth_};
  d.push = vk::push_bytes(push);
  d.groups[0] = probes;
  return d;
}

Status GpuIntegrator::dispatch(const kernels::RaySample* samples, const std::vector<uint32_t>& counts,
                               size_t first_probe, size_t probe_count, uint64_t first_sample, uint64_t sample_count,
                               GpuIntegrateResult& out) {
  if (samples) GIBAKE_TRY(ensure_samples(std::max<uint64_t>(1, sample_count)));
  // Uploaded samples start the buffer; resident ones sit where the writing kernel put them.
  const std::vector<gpu::GpuIntegrateProbe> table =
      probe_table(&counts[first_probe], probe_count, samples ? 0u : uint32_t(first_sample), paired_);
  if (samples && sample_count > 0)
    GIBAKE_TRY(vk_.upload(samples_, samples + first_sample, sample_count * sizeof(gpu::GpuRaySample)));
  GIBAKE_TRY(vk_.upload(probes_, table.data(), table.size() * sizeof(table[0])));
  const vk::Dispatch d = integrate_dispatch(uint32_t(probe_count));
  std::vector<double> seconds;
  GIBAKE_TRY(vk_.run({d}, &seconds));
  seconds_ += seconds.empty() ? 0.0 : seconds[0];
  const uint64_t sh_bytes = uint64_t(probe_count) * coefs_ * 3 * 4, irr_bytes = probe_count * kIrrValues * 4,
                 depth_bytes = probe_count * kDepthValues * 4;
  bytes_ +=
      sample_count * sizeof(gpu::GpuRaySample) + table.size() * sizeof(table[0]) + sh_bytes + irr_bytes + depth_bytes;
  GIBAKE_TRY(vk_.download(sh_, &out.sh[first_probe * coefs_ * 3], sh_bytes));
  GIBAKE_TRY(vk_.download(irr_, &out.irradiance[first_probe * kIrrValues], irr_bytes));
  return vk_.download(depth_, &out.depth[first_probe * kDepthValues], depth_bytes);
}

}  // namespace gibake
