// The probe-feedback bounce passes on a Vulkan device: kernels/shaders/bounce_weights.comp (the
// twin of kernels::ddgi_probe_weights) once, then kernels/shaders/bounce_pass.comp per pass (the
// twin of run_bounce_passes' per-probe body), SH ping-ponging on the device. Hits, depth tiles and
// the probe table are uploaded once and only the final SH and irradiance texels come back, unless
// the hits do not fit one chunk: then every pass streams the hits through a fixed buffer and
// recomputes their weights (the same bits), so device memory is bounded for any probe count.
// Vulkan and kernels only (bench/gpu links it without TBB); the CPU/GPU switch is run_bounces in
// bake/ddgi/ddgi.cpp.
#pragma once
#include <cstdint>
#include <vector>

#include "bake/ddgi/bounce.h"
#include "io/status.h"
#include "kernels/ddgi_sample.h"
#include "kernels/vulkan/context.h"

namespace gibake {

struct GpuBounceOptions {
  uint64_t chunk_hits = uint64_t(1) << 21;  // hits (48 bytes) and their weights (64 bytes) on the device at once
  uint64_t memory_limit = 0;                // bytes the passes may allocate; 0: the device's memory
};

struct GpuBounceStats {
  double weights_seconds = 0.0;  // device time of the weights kernel (every chunk, every pass)
  double pass_seconds = 0.0;     // device time of the pass kernel
  uint32_t chunks = 0;           // hit chunks (1: everything resident, one submission)
  uint32_t submissions = 0;
  uint64_t device_bytes = 0;  // device memory the passes allocated
};

// Same inputs and results as run_bounce_passes (in.volume.depth_tiles and in.positions required).
// Fails before allocating, naming the bytes, when the per-probe data and one chunk do not fit.
Status run_bounce_passes_gpu(vk::Context& vk, const BounceInputs& in, std::vector<float>& sh,
                             std::vector<float>& irradiance, GpuBounceStats& stats,
                             const GpuBounceOptions& options = {});

// The weights kernel alone: every bouncing hit's weights, flattened probe after probe (as
// run_bounce_passes computes them), for testing against kernels::ddgi_probe_weights.
Status gpu_bounce_weights(vk::Context& vk, const BounceInputs& in, std::vector<kernels::ProbeWeights>& out,
                          const GpuBounceOptions& options = {});

}  // namespace gibake
