// Probe-ray integration on a Vulkan device: kernels/shaders/integrate.comp, the twin of
// kernels::integrate_radiance (SH, 8x8 irradiance texels) and kernels::integrate_depth (16x16 depth
// moments with the pow(dot, 64) cone) for many probes in one dispatch, timed with timestamp queries.
// Device memory is bounded: probes stream through fixed sample and output buffers.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "kernels/integrate.h"
#include "kernels/shaders/gpu_types.h"
#include "kernels/vulkan/context.h"

namespace gibake {

// Per probe, in the order of the call's probes: the CPU kernels' output layouts.
struct GpuIntegrateResult {
  std::vector<float> sh;          // coefficients x RGB (sh_coefficient_count(order) * 3)
  std::vector<float> irradiance;  // 64 texels x RGB, lux
  std::vector<float> depth;       // 256 texels x (mean, mean^2), unbordered
};

struct IntegrateRecorded;  // bake/vulkan/path_pipeline.h

class GpuIntegrator {
 public:
  ~GpuIntegrator();
  GpuIntegrator(const GpuIntegrator&) = delete;
  GpuIntegrator& operator=(const GpuIntegrator&) = delete;

  // `batch_samples` and `batch_probes` bound one dispatch (a probe with more samples gets a batch
  // of its own, the sample buffer grown to fit it).
  static Status create(vk::Context& vk, int sh_order, std::unique_ptr<GpuIntegrator>& out,
                       uint64_t batch_samples = uint64_t(1) << 20, uint32_t batch_probes = 8192);

  // `counts[i]` samples of probe i, the probes' samples one after another. `paired`: probe i has
  // 2 counts[i] samples, its rays then their emitter samples (bake/trace/path_gather.h), integrated
  // as kernels::integrate_radiance does with norm_count = counts[i], depth from the rays only.
  Status integrate(const kernels::RaySample* samples, const std::vector<uint32_t>& counts, GpuIntegrateResult& out,
                   bool paired = false);
  // The device-resident route: another kernel (path.comp) writes the samples into sample_buffer,
  // sized here for `count` samples, where a recorded integration reads them (record_resident,
  // record_accumulate): no sample crosses the bus.
  Status reserve_samples(uint64_t count, vk::Buffer*& sample_buffer);

  // The asynchronous route (defined in bake/vulkan/integrate_record.cpp): the resident samples of
  // `counts` (at most batch_probes() probes, the samples reserved before any chunk is in flight)
  // integrated as steps of `rec`; their integrals read back once `rec` has run. `paired`: probe i
  // has 2 counts[i] samples, its rays then their light samples, integrated as kernels::
  // integrate_radiance does with norm_count = counts[i], depth from the rays only.
  Status record_resident(const std::vector<uint32_t>& counts, vk::Recording& rec, IntegrateRecorded& out,
                         bool paired = false);
  void collect(const vk::Recording& rec, const IntegrateRecorded& recorded, GpuIntegrateResult& out);

  // --target-error on the device: each probe's integrals accumulate pass by pass in its slot
  // (slots [0, slots), made before any chunk is in flight), nothing read back until the end.
  // record_accumulate: one pass of a chunk, probe i of `probes` with `rays` new rays resident at
  // i * rays (paired: 2 i rays, its rays then their light samples) and probes[i].total rays over its
  // passes so far, these included (the first pass when total == rays); its outputs normalized by
  // total. The slots' outputs, final once a probe's last pass has run, come back with read_slots.
  struct AccumulateProbe {
    uint32_t slot = 0, total = 0;
  };
  Status reserve_accumulators(size_t slots);
  // Room for chunks of `probes` probes of `samples_per_probe` samples each on the resident route:
  // a probe of more samples than one window carries its sums between windows in its slot's
  // accumulators (made before any chunk is in flight).
  Status reserve_windows(size_t probes, uint64_t samples_per_probe);
  Status record_accumulate(const std::vector<AccumulateProbe>& probes, uint32_t rays, vk::Recording& rec,
                           IntegrateRecorded& out, bool paired);
  Status read_slots(size_t first, size_t count, GpuIntegrateResult& out);
  // A slot's accumulators: two vec4s per invocation of its workgroup (integrate.comp).
  static constexpr uint64_t kAccumulatorBytes = uint64_t(GPU_INTEGRATE_GROUP) * 2 * 16;
  // Device bytes the accumulators and outputs of `slots` slots take (the route's footprint).
  uint64_t accumulator_bytes(size_t slots) const;
  uint32_t batch_probes() const { return batch_probes_; }

  int sh_values() const { return coefs_ * 3; }
  // Totals over every dispatch so far: kernel time (timestamps) and the bytes the kernel must move
  // (samples and probe table read, SH, texels and moments written): their ratio is its bandwidth.
  double kernel_seconds() const { return seconds_; }
  uint64_t kernel_bytes() const { return bytes_; }

 private:
  explicit GpuIntegrator(vk::Context& vk) : vk_(vk) {}
  Status ensure_samples(uint64_t count);
  // Dispatches every probe of `counts` in uploaded batches.
  Status integrate_batches(const kernels::RaySample* samples, const std::vector<uint32_t>& counts,
                           GpuIntegrateResult& out);
  // Output buffers for `slots` probes (grow, never shrink).
  Status ensure_outputs(size_t slots);
  // The kernel's per-probe table for counts[0..n): probe i's samples from `first_sample` on, 2 a
  // ray when `paired`, the CPU's norm 4pi/rays, the rays that feed the depth moments; output slot i.
  static std::vector<gpu::GpuIntegrateProbe> probe_table(const uint32_t* counts, size_t n, uint32_t first_sample,
                                                         bool paired);
  // The windows of GPU_RAY_WINDOW samples a probe of `samples_per_probe` samples takes (1 at least).
  static uint32_t windows(uint64_t samples_per_probe);
  // The integration kernel over `probes` probes of the table and samples uploaded, one dispatch per
  // window of the most samples a probe has; to run in order.
  std::vector<vk::Dispatch> integrate_dispatches(uint32_t probes, uint64_t samples_per_probe);
  Status dispatch(const kernels::RaySample* samples, const std::vector<uint32_t>& counts, size_t first_probe,
                  size_t probe_count, uint64_t first_sample, uint64_t sample_count, GpuIntegrateResult& out);

  vk::Context& vk_;
  int coefs_ = 0;
  float cos_cutoff_ = 1.f;
  uint64_t batch_samples_ = 0, sample_capacity_ = 0;
  uint32_t batch_probes_ = 0;
  size_t out_capacity_ = 0, acc_capacity_ = 0;  // slots of the output buffers and accumulators
  bool paired_ = false;  // the call's probes have paired emitter samples
  double seconds_ = 0.0;
  uint64_t bytes_ = 0;
  vk::Buffer samples_, probes_, irr_dirs_, depth_dirs_, sh_, irr_, depth_, acc_;
  vk::Pipeline pipeline_;
};

}  // namespace gibake
