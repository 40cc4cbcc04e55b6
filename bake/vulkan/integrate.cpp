#include "bake/vulkan/integrate.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "bake/vulkan/pipelines.h"
#include "io/results/ddgi_result.h"
#include "kernels/sh.h"
#include "kernels/shaders/gpu_types.h"

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
  // One workgroup per probe, in x: within the device's maxComputeWorkGroupCount[0].
  g->batch_probes_ = std::clamp<uint32_t>(batch_probes, 1, vk.limits().group_count[0]);
  const uint64_t np = g->batch_probes_;
  GIBAKE_TRY(vk.create_buffer(irr.size() * sizeof(gpu::vec4), g->irr_dirs_, "irradiance texel directions"));
  GIBAKE_TRY(vk.upload(g->irr_dirs_, irr.data(), irr.size() * sizeof(gpu::vec4)));
  GIBAKE_TRY(vk.create_buffer(dep.size() * sizeof(gpu::vec4), g->depth_dirs_, "depth texel directions"));
  GIBAKE_TRY(vk.upload(g->depth_dirs_, dep.data(), dep.size() * sizeof(gpu::vec4)));
  GIBAKE_TRY(vk.create_buffer(np * sizeof(gpu::GpuIntegrateProbe), g->probes_, "integration probe table"));
  GIBAKE_TRY(g->ensure_outputs(np));
  GIBAKE_TRY(g->reserve_accumulators(1));  // bound whether or not a probe accumulates
  GIBAKE_TRY(g->ensure_samples(g->batch_samples_));
  GIBAKE_TRY(vk.create_pipeline(pipelines::integrate(), g->pipeline_));
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

Status GpuIntegrator::ensure_outputs(size_t slots) {
  if (slots <= out_capacity_) return Status::ok();
  GIBAKE_TRY(vk_.create_buffer(slots * coefs_ * 3 * 4, sh_, "integration SH"));
  GIBAKE_TRY(vk_.create_buffer(slots * kIrrValues * 4, irr_, "integration irradiance texels"));
  GIBAKE_TRY(vk_.create_buffer(slots * kDepthValues * 4, depth_, "integration depth moments"));
  out_capacity_ = slots;
  return Status::ok();
}

uint64_t GpuIntegrator::accumulator_bytes(size_t slots) const {
  return uint64_t(slots) * (kAccumulatorBytes + (uint64_t(coefs_) * 3 + kIrrValues + kDepthValues) * 4);
}

Status GpuIntegrator::reserve_accumulators(size_t slots) {
  GIBAKE_TRY(ensure_outputs(slots));
  if (slots <= acc_capacity_) return Status::ok();
  GIBAKE_TRY(vk_.create_buffer(slots * kAccumulatorBytes, acc_, "integration accumulators"));
  acc_capacity_ = slots;
  return Status::ok();
}

Status GpuIntegrator::read_slots(size_t first, size_t count, GpuIntegrateResult& out) {
  if (first + count > out_capacity_)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "integration slots read past their buffers");
  const uint64_t sh = uint64_t(coefs_) * 3 * 4, irr = kIrrValues * 4, depth = kDepthValues * 4;
  out.sh.resize(count * coefs_ * 3);
  out.irradiance.resize(count * kIrrValues);
  out.depth.resize(count * kDepthValues);
  GIBAKE_TRY(vk_.download(sh_, out.sh.data(), count * sh, first * sh));
  GIBAKE_TRY(vk_.download(irr_, out.irradiance.data(), count * irr, first * irr));
  return vk_.download(depth_, out.depth.data(), count * depth, first * depth);
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

Status GpuIntegrator::integrate_batches(const kernels::RaySample* samples, const std::vector<uint32_t>& counts,
                                        GpuIntegrateResult& out) {
  const size_t n = counts.size();
  out.sh.assign(n * coefs_ * 3, 0.f);
  out.irradiance.assign(n * kIrrValues, 0.f);
  out.depth.assign(n * kDepthValues, 0.f);
  // Greedy batches: as many whole probes as fit the probe limit and the sample limit (at least one).
  const uint64_t limit = batch_samples_;
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
    table[i].acc = {uint32_t(i), 0u, 0u, 0u};
    at += total;
  }
  return table;
}

uint32_t GpuIntegrator::windows(uint64_t samples_per_probe) {
  return uint32_t(std::max<uint64_t>(1, (samples_per_probe + GPU_RAY_WINDOW - 1) / GPU_RAY_WINDOW));
}

Status GpuIntegrator::reserve_windows(size_t probes, uint64_t samples_per_probe) {
  return windows(samples_per_probe) > 1 ? reserve_accumulators(probes) : Status::ok();
}

std::vector<vk::Dispatch> GpuIntegrator::integrate_dispatches(uint32_t probes, uint64_t samples_per_probe) {
  std::vector<vk::Dispatch> out;
  for (uint32_t w = 0; w < windows(samples_per_probe); ++w) {
    const gpu::IntegratePush push{{probes, uint32_t(coefs_), w * GPU_RAY_WINDOW, GPU_RAY_WINDOW},
                                  {cos_cutoff_, 0.f, 0.f, 0.f}};
    vk::Dispatch d;
    d.pipeline = &pipeline_;
    d.buffers = {&samples_, &probes_, &irr_dirs_, &depth_dirs_, &sh_, &irr_, &depth_, &acc_};
    d.push = vk::push_bytes(push);
    d.groups[0] = probes;
    out.push_back(std::move(d));
  }
  return out;
}

Status GpuIntegrator::dispatch(const kernels::RaySample* samples, const std::vector<uint32_t>& counts,
                               size_t first_probe, size_t probe_count, uint64_t first_sample, uint64_t sample_count,
                               GpuIntegrateResult& out) {
  GIBAKE_TRY(ensure_samples(std::max<uint64_t>(1, sample_count)));
  const std::vector<gpu::GpuIntegrateProbe> table = probe_table(&counts[first_probe], probe_count, 0u, paired_);
  uint64_t most = 0;  // the most samples of a probe: the windows the kernel takes
  for (const gpu::GpuIntegrateProbe& t : table) most = std::max<uint64_t>(most, t.range.y);
  GIBAKE_TRY(reserve_windows(probe_count, most));
  if (sample_count > 0)
    GIBAKE_TRY(vk_.upload(samples_, samples + first_sample, sample_count * sizeof(gpu::GpuRaySample)));
  GIBAKE_TRY(vk_.upload(probes_, table.data(), table.size() * sizeof(table[0])));
  std::vector<double> seconds;
  GIBAKE_TRY(vk_.run(integrate_dispatches(uint32_t(probe_count), most), &seconds));
  for (double t : seconds) seconds_ += t;
  const uint64_t sh_bytes = uint64_t(probe_count) * coefs_ * 3 * 4, irr_bytes = probe_count * kIrrValues * 4,
                 depth_bytes = probe_count * kDepthValues * 4;
  bytes_ +=
      sample_count * sizeof(gpu::GpuRaySample) + table.size() * sizeof(table[0]) + sh_bytes + irr_bytes + depth_bytes;
  GIBAKE_TRY(vk_.download(sh_, &out.sh[first_probe * coefs_ * 3], sh_bytes));
  GIBAKE_TRY(vk_.download(irr_, &out.irradiance[first_probe * kIrrValues], irr_bytes));
  return vk_.download(depth_, &out.depth[first_probe * kDepthValues], depth_bytes);
}

}  // namespace gibake
