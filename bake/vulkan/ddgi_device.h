// The DDGI device contract (bake/ddgi/ddgi_device.h) on a Vulkan device: relocation sums, probe
// paths, integration and statistics, and the bounce passes as compute kernels over the session's BVH.
#pragma once
#include <tbb/task_arena.h>

#include <memory>

#include "bake/ddgi/ddgi_device.h"
#include "bake/vulkan/session.h"

namespace gibake {

// `session` holds a device (and, for relocation and tracing, the scene's BVH); it outlives the device. Host work
// between kernels runs in `arena`.
std::unique_ptr<DdgiDevice> make_vulkan_ddgi_device(GpuSession& session, tbb::task_arena& arena);

}  // namespace gibake
