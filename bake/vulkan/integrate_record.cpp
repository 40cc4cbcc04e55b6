// GpuIntegrator's asynchronous route: one chunk's resident samples integrated as steps of a
// vk::Recording (bake/vulkan/path_pipeline.h), the integrals downloaded in the same submission; or,
// with --target-error, accumulated in the probes' slots pass after pass.
#include <algorithm>
#include <cstring>
#include <string>

#include "bake/vulkan/integrate.h"
#include "bake/vulkan/path_pipeline.h"
#include "io/results/ddgi_result.h"
#include "kernels/shaders/gpu_types.h"

namespace gibake {

Status GpuIntegrator::record_resident(const std::vector<uint32_t>& counts, vk::Recording& rec, IntegrateRecorded& out,
                                      bool paired) {
  const size_t n = counts.size();
  const uint32_t per_ray = paired ? 2u : 1u;  // samples per ray: with its paired light sample, 2
  uint64_t total = 0;
  for (uint32_t c : counts) total += uint64_t(c) * per_ray;
  uint64_t most = 0;
  for (uint32_t c : counts) most = std::max<uint64_t>(most, uint64_t(c) * per_ray);
  if (n > batch_probes_ || total > sample_capacity_ || (windows(most) > 1 && n > acc_capacity_))
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         "a recorded integration of " + std::to_string(n) + " probes and " + std::to_string(total) +
                             " samples exceeds its buffers");
  out = IntegrateRecorded{};
  out.probes = n;
  out.table = probe_table(counts.data(), n, 0u, paired);
  if (n == 0) return Status::ok();
  rec.upload(probes_, out.table.data(), n * sizeof(gpu::GpuIntegrateProbe));
  for (vk::Dispatch& d : integrate_dispatches(uint32_t(n), most)) out.dispatches.push_back(rec.dispatch(std::move(d)));
  out.sh = rec.download(sh_, uint64_t(n) * coefs_ * 3 * 4);
  out.irradiance = rec.download(irr_, uint64_t(n) * GPU_IRRADIANCE_TEXELS * 3 * 4);
  out.depth = rec.download(depth_, uint64_t(n) * GPU_DEPTH_TEXELS * 2 * 4);
  out.samples = total;
  return Status::ok();
}

Status GpuIntegrator::record_accumulate(const std::vector<AccumulateProbe>& probes, uint32_t rays, vk::Recording& rec,
                                        IntegrateRecorded& out, bool paired) {
  const size_t n = probes.size();
  const uint32_t per_probe = rays * (paired ? 2u : 1u);
  if (n > batch_probes_ || uint64_t(n) * per_probe > sample_capacity_)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         "an accumulated integration of " + std::to_string(n) + " probes exceeds its buffers");
  out = IntegrateRecorded{};
  out.probes = n;
  out.downloads = false;
  out.samples = uint64_t(n) * per_probe;
  out.table.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const AccumulateProbe& a = probes[i];
    if (a.slot >= acc_capacity_ || a.total < rays)
      return Status::error(ExitCode::RuntimeFailure, "", "vulkan", "an accumulated probe outside its slots");
    // The norm of every ray so far, 4pi/total (probe_table's rule); this pass's samples at i * per_probe.
    out.table[i] = probe_table(&a.total, 1, uint32_t(i * per_probe), paired)[0];
    out.table[i].range.y = per_probe;
    out.table[i].range.w = rays;
    out.table[i].acc = {a.slot, (a.total > rays ? GPU_ACC_LOAD : 0u) | GPU_ACC_STORE, 0u, 0u};
  }
  if (n == 0) return Status::ok();
  rec.upload(probes_, out.table.data(), n * sizeof(gpu::GpuIntegrateProbe));
  for (vk::Dispatch& d : integrate_dispatches(uint32_t(n), per_probe)) out.dispatches.push_back(rec.dispatch(std::move(d)));
  return Status::ok();
}

void GpuIntegrator::collect(const vk::Recording& rec, const IntegrateRecorded& r, GpuIntegrateResult& out) {
  const size_t n = r.probes;
  if (!r.downloads) {  // accumulated: the integrals stay in their slots
    for (size_t i : r.dispatches) seconds_ += rec.dispatch_seconds()[i];
    // Samples and table read, accumulators read and written, outputs written.
    bytes_ += r.samples * sizeof(gpu::GpuRaySample) + n * (sizeof(gpu::GpuIntegrateProbe) + kAccumulatorBytes) +
              accumulator_bytes(n);
    return;
  }
  auto copy = [&](std::vector<float>& v, size_t index, size_t values) {
    v.resize(values);
    if (values) std::memcpy(v.data(), rec.result(index), values * 4);
  };
  copy(out.sh, r.sh, n * coefs_ * 3);
  copy(out.irradiance, r.irradiance, n * GPU_IRRADIANCE_TEXELS * 3);
  copy(out.depth, r.depth, n * GPU_DEPTH_TEXELS * 2);
  if (n == 0) return;
  for (size_t i : r.dispatches) seconds_ += rec.dispatch_seconds()[i];
  bytes_ += r.samples * sizeof(gpu::GpuRaySample) + n * sizeof(gpu::GpuIntegrateProbe) +
            (out.sh.size() + out.irradiance.size() + out.depth.size()) * 4;
}

}  // namespace gibake
