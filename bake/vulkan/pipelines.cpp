#include "bake/vulkan/pipelines.h"

#include "kernels/shaders/gpu_types.h"
#include "kernels/shaders/integrate_spv.h"
#include "kernels/shaders/path_probe_field_spv.h"
#include "kernels/shaders/path_spv.h"
#include "kernels/shaders/probe_field_ended_spv.h"
#include "kernels/shaders/probe_stats_spv.h"
#include "kernels/shaders/raygen_spv.h"
#include "kernels/shaders/reference_sums_spv.h"
#include "kernels/shaders/reloc_sums_spv.h"
#include "kernels/shaders/traverse_spv.h"

namespace gibake::pipelines {

namespace {

template <size_t N>
vk::PipelineSpec spec(const uint32_t (&spirv)[N], uint32_t bindings, uint32_t push_bytes, const char* name,
                      uint32_t shared_bytes = 0) {
  return {spirv, N, bindings, push_bytes, name, shared_bytes};
}

}  // namespace

vk::PipelineSpec traverse() { return spec(shaders::traverse_spv, 8, sizeof(gpu::TraversePush), "traverse"); }
vk::PipelineSpec reloc_sums() { return spec(shaders::reloc_sums_spv, 4, sizeof(gpu::RelocSumsPush), "reloc_sums"); }
vk::PipelineSpec path() { return spec(shaders::path_spv, 25, sizeof(gpu::PathPush), "path"); }
// path.comp's 25 and the paths' first hits.
vk::PipelineSpec path_probe_field() {
  return spec(shaders::path_probe_field_spv, 26, sizeof(gpu::PathPush), "path_probe_field");
}
// The first hits and probe_field.glsl's four.
vk::PipelineSpec probe_field_ended() { return spec(shaders::probe_field_ended_spv, 5, 16, "probe_field_ended"); }
vk::PipelineSpec raygen() { return spec(shaders::raygen_spv, 4, sizeof(gpu::RayGenPush), "raygen"); }
vk::PipelineSpec probe_stats() { return spec(shaders::probe_stats_spv, 3, sizeof(gpu::ProbeStatsPush), "probe_stats"); }
// integrate.comp's shared tile: s_dir and s_rad, a vec4 each per invocation.
vk::PipelineSpec integrate() {
  return spec(shaders::integrate_spv, 8, sizeof(gpu::IntegratePush), "integrate", GPU_INTEGRATE_GROUP * 32);
}
vk::PipelineSpec reference_sums() {
  return spec(shaders::reference_sums_spv, 3, sizeof(gpu::ReferenceSumsPush), "reference_sums");
}

void create_ddgi_pipelines_beside(vk::Context& vk, bool probe_field) {
  // Not on a CPU device (lavapipe): there the compile takes the cores the bake runs on, and holds
  // relocation's submissions back until it is done.
  if (!vk.device().is_gpu()) return;
  std::vector<vk::PipelineSpec> specs = {traverse(), reloc_sums(), path(), raygen()};
  if (vk.shader_float64()) specs.push_back(probe_stats());
  specs.push_back(integrate());
  specs.push_back(reference_sums());
  if (probe_field) {
    specs.push_back(path_probe_field());
    specs.push_back(probe_field_ended());
  }
  vk.create_pipelines_beside(std::move(specs));
}

}  // namespace gibake::pipelines
