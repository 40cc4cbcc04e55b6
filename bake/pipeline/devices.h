// The registration point of backends: for each bake kind, the one place that picks the device its
// stages run on. The contracts live with their kinds (bake/ddgi/ddgi_device.h,
// bake/lpv/lpv_device.h), the CPU implementations beside them (the reference), the Vulkan ones in
// bake/vulkan/. A new backend is one folder implementing the contracts plus one branch in each
// function here; a new bake kind is one folder plus one function here. The stages get their
// devices from here (PipelineDevices for the DDGI bake and the merge, make_lpv_device for the LPV).
#pragma once
#include <tbb/task_arena.h>

#include <memory>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/ddgi_device.h"
#include "bake/run/backend.h"
#include "io/context.h"
#include "io/status.h"

namespace gibake {

struct GpuSession;
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

// The DDGI bake's and the merge's platform (bake/ddgi/ddgi_device.h): the set-up of
// bake/pipeline/bake_setup.h and the devices above.
class PipelineDevices final : public DdgiPlatform {
 public:
  Status build_setup(const Scene& scene, const SetupSettings& settings, VulkanWarmup* warmup,
                     const BakeSetupParts& parts, const Context& ctx, tbb::task_arena& arena,
                     BakeSetup& out) const override;
  std::unique_ptr<DdgiDevice> device(GpuSession& session, tbb::task_arena& arena) const override;
  Status open_session(const BackendSettings& settings, std::shared_ptr<GpuSession>& out,
                      BackendChoice& choice) const override;
  ReleaseBeside* release_thread(GpuSession& session) const override;
};

// A DDGI bake on PipelineDevices that builds everything it needs itself (tests, tools).
Status bake_ddgi(const Scene& scene, const DdgiSettings& settings, const Context& ctx, DdgiResult& result,
                 DdgiReport& report);

}  // namespace gibake
