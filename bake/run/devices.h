// The registration point of backends: for each bake kind, the one place that picks the device its
// stages run on. The contracts live with their kinds (bake/ddgi/ddgi_device.h,
// bake/lpv/lpv_device.h), the CPU implementations beside them (the reference), the Vulkan ones in
// bake/vulkan/. A new backend is one folder implementing the contracts plus one branch in each
// function here; a new bake kind is one folder plus one function here.
#pragma once
#include <tbb/task_arena.h>

#include <memory>

#include "bake/run/backend.h"
#include "io/context.h"
#include "io/status.h"

namespace gibake {

struct GpuSession;
class DdgiDevice;
class LpvDevice;
class ReferencePathDevice;

// An open device session for `settings` (its backend resolved; empty on the CPU), for callers that
// hold none yet (the shard merge's bounce passes).
Status open_device_session(const BackendSettings& settings, std::shared_ptr<GpuSession>& out);
// The backend and device a session was opened for.
const BackendChoice& session_choice(const GpuSession& session);

// The DDGI bake's device: Vulkan when `session` holds a device, else the CPU in `arena`. Tracing
// needs the session's scene too (build_gpu_session_bvh, upload_gpu_session_scene); the bounce passes need only the
// device.
std::unique_ptr<DdgiDevice> make_ddgi_device(GpuSession& session, tbb::task_arena& arena);

// The device for the reconstruction check's reference paths (bake/preview/reconstruction_check.h):
// the session's, when its DDGI trace ran there and kept its path tracer; null (the CPU) otherwise.
// It holds the session until it goes.
std::unique_ptr<ReferencePathDevice> make_reference_path_device(std::shared_ptr<GpuSession> session);

// The LPV propagation's device for `settings.backend`: the DDGI bake's session when it is open on
// the same device (one Vulkan context a process), else a context of its own; the CPU otherwise.
// `choice` gets what was chosen.
Status make_lpv_device(const BackendSettings& settings, GpuSession* session, const Context& ctx,
                       std::unique_ptr<LpvDevice>& out, BackendChoice& choice);

}  // namespace gibake
