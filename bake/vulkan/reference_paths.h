// The reconstruction check's reference paths on the Vulkan device that baked the probes
// (bake/preview/reconstruction_check.h ReferencePathDevice): the trace's path tracer, kept by the
// session after the trace (GpuSession::reference_tracer), makes each point's paths and traces them
// in path.comp's mode 2 (trace_radiance's twin), and reference_sums.comp sums them per point: on a
// GPU that is several times faster than the CPU's path tracing (docs/BENCHMARKS.md).
#pragma once
#include <memory>

#include "bake/preview/reconstruction_check.h"
#include "bake/vulkan/session.h"

namespace gibake {

// Null when the session kept no path tracer (a CPU bake, or no DDGI trace on the device), and on a
// CPU device (lavapipe) unless `cpu_device_too` (tests): there the host's own path tracer is faster
// (lavapipe runs the same paths on the same cores, through an emulated GPU). The device
// holds the session: whoever ends it last closes the device, so hand it to the session's closing thread once the
// reference is traced.
std::unique_ptr<ReferencePathDevice> make_gpu_reference_paths(std::shared_ptr<GpuSession> session,
                                                              bool cpu_device_too = false);

}  // namespace gibake
