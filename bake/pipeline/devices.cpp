#include "bake/pipeline/devices.h"

#include "bake/pipeline/bake_setup.h"
#include "bake/lpv/lpv_device.h"
#include "bake/vulkan/ddgi_device.h"
#include "bake/vulkan/lpv.h"
#include "bake/vulkan/reference_paths.h"
#include "bake/vulkan/session.h"

namespace gibake {

Status open_device_session(const BackendSettings& settings, std::shared_ptr<GpuSession>& out) {
  out = std::make_shared<GpuSession>();
  return open_gpu_device(settings, *out);
}

const BackendChoice& session_choice(const GpuSession& session) { return session.choice; }

std::unique_ptr<DdgiDevice> make_ddgi_device(GpuSession& session, tbb::task_arena& arena) {
  if (session.vk) return make_vulkan_ddgi_device(session, arena);
  return make_cpu_ddgi_device(session.choice, arena);
}

std::unique_ptr<ReferencePathDevice> make_reference_path_device(std::shared_ptr<GpuSession> session) {
  return make_gpu_reference_paths(std::move(session));
}

Status make_lpv_device(const BackendSettings& settings, GpuSession* session, const Context& ctx,
                       std::unique_ptr<LpvDevice>& out, BackendChoice& choice) {
  // auto: the LPV follows the DDGI bake (its device when it ran on one), else the CPU.
  if (settings.backend == Backend::Auto && session && session->vk)
    choice = session->choice;
  else
    GIBAKE_TRY(resolve_backend(settings, choice));
  if (choice.backend != Backend::Vulkan) {
    out = make_cpu_lpv_device();
    return Status::ok();
  }
  const bool shared = session && session->vk && session->choice.device.index == choice.device.index;
  if (shared) {
    ctx.note("vulkan: LPV propagation on the DDGI bake's device context");
    out = make_vulkan_lpv_device(*session->vk, nullptr);
    return Status::ok();
  }
  std::unique_ptr<vk::Context> own;
  GIBAKE_TRY(open_vulkan(choice, settings, own));
  vk::Context& vk = *own;
  out = make_vulkan_lpv_device(vk, std::move(own));
  return Status::ok();
}

Status PipelineDevices::build_setup(const Scene& scene, const SetupSettings& settings, VulkanWarmup* warmup,
                                    const BakeSetupParts& parts, const Context& ctx, tbb::task_arena& arena,
                                    BakeSetup& out) const {
  return build_bake_setup(scene, settings, warmup, parts, ctx, arena, out);
}

std::unique_ptr<DdgiDevice> PipelineDevices::device(GpuSession& session, tbb::task_arena& arena) const {
  return make_ddgi_device(session, arena);
}

Status PipelineDevices::open_session(const BackendSettings& settings, std::shared_ptr<GpuSession>& out,
                                     BackendChoice& choice) const {
  GIBAKE_TRY(open_device_session(settings, out));
  choice = out->choice;
  return Status::ok();
}

ReleaseBeside* PipelineDevices::release_thread(GpuSession& session) const {
  return session.active() ? &session.released : nullptr;
}

Status bake_ddgi(const Scene& scene, const DdgiSettings& settings, const Context& ctx, DdgiResult& result,
                 DdgiReport& report) {
  const PipelineDevices platform;
  RunContext run;
  run.platform = &platform;
  return bake_ddgi(scene, settings, run, ctx, result, report);
}

}  // namespace gibake
