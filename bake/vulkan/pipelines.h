// The DDGI bake's compute pipelines as specs (their SPIR-V, bindings, push constants), so that the
// kernels' owners create them from one place and the set-up can have the driver make them ahead,
// beside the uploads (vk::Context::create_pipelines_beside).
#pragma once
#include "kernels/vulkan/context.h"

namespace gibake::pipelines {

vk::PipelineSpec traverse();        // bake/vulkan/traverse.h
vk::PipelineSpec reloc_sums();      // bake/vulkan/relocate.h
vk::PipelineSpec path();            // bake/vulkan/path.h
vk::PipelineSpec raygen();          // bake/vulkan/raygen.h
vk::PipelineSpec probe_stats();     // bake/vulkan/probe_stats.h (devices with shaderFloat64)
vk::PipelineSpec integrate();       // bake/vulkan/integrate.h
vk::PipelineSpec reference_sums();  // bake/vulkan/reference_paths.h
// bake/vulkan/path.h: the surface fit's paths, where they would end in a bake's probes recorded too,
// and those first hits lit by the probes.
vk::PipelineSpec path_probe_field();
vk::PipelineSpec probe_field_ended();

// Every pipeline a probe bake on `vk` creates, in the order it needs them, made on the context's
// own thread from now on; nothing on a CPU device. `probe_field`: the surface fit's paths end in the
// probes too (path_probe_field, probe_field_ended).
void create_ddgi_pipelines_beside(vk::Context& vk, bool probe_field = false);

}  // namespace gibake::pipelines
