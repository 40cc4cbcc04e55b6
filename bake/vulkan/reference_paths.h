// The reconstruction check's reference paths on the Vulkan device that baked the probes
// (bake/preview/reconstruction_check.h ReferencePathDevice): the trace's path tracer, kept by the
// session after the trace (GpuSession::reference_tracer), traces them in path.comp's mode 2, the
// twin of trace_radiance. The check then costs a few milliseconds of device time instead of the
// CPU's path tracing after the trace (docs/BENCHMARKS.md).
#pragma once
#include <memory>

#include "bake/preview/reconstruction_check.h"
#include "bake/vulkan/session.h"

namespace gibake {

// Null when the session kept no path tracer (a CPU bake, or no DDGI trace on the device), and on a
// CPU device (lavapipe) unless `cpu_device_too` (tests): there the host's own path tracer is faster
// (0.18 s against 2.4 s for the sample's check on this project's 2-core VM). The device holds the
// session: whoever ends it last closes the device, so hand it to the session's closing thread once
// the reference is traced.
std::unique_ptr<ReferencePathDevice> make_gpu_reference_paths(std::shared_ptr<GpuSession> session,
                                                              bool cpu_device_too = false);

}  // namespace gibake
