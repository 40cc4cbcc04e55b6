#include "bake/vulkan/lpv.h"

#include <string>

#include "kernels/shaders/gpu_types.h"
#include "kernels/shaders/lpv_propagate_spv.h"
#include "kernels/shaders/lpv_scale_spv.h"

namespace gibake {
using kernels::LpvCell;

static_assert(sizeof(gpu::GpuLpvCell) == sizeof(LpvCell), "GpuLpvCell mirrors kernels::LpvCell");

Status lpv_propagate_volume_gpu(vk::Context& vk, const kernels::LpvGrid& grid, const std::vector<LpvCell>& cells,
                                const float* geometry, int iterations, std::vector<LpvCell>& accumulated) {
  const size_t n = grid.cells();
  if (cells.size() != n) return Status::error(ExitCode::RuntimeFailure, "", "lpv", "cell count mismatch");
  const size_t corners = size_t(grid.dims[0] + 1) * size_t(grid.dims[1] + 1) * size_t(grid.dims[2] + 1);
  const uint64_t cell_bytes = n * sizeof(LpvCell);
  const uint64_t need = 3 * cell_bytes + n * 16 + (geometry ? corners * 16 : 16);
  GIBAKE_TRY(vk.check_device_memory(need, 0, "LPV propagation",
                                     "a smaller --lpv-res lowers it; --backend cpu bakes without the device"));
  float table[6 * 5 * 8];
  kernels::lpv_face_table_export(table);
  vk::Buffer a, b, acc, scale, faces, geo;
  GIBAKE_TRY(vk.create_buffer(cell_bytes, a, "LPV cells"));
  GIBAKE_TRY(vk.create_buffer(cell_bytes, b, "LPV cells"));
  GIBAKE_TRY(vk.create_buffer(cell_bytes, acc, "LPV accumulation"));
  GIBAKE_TRY(vk.create_buffer(n * 16, scale, "LPV flux scale"));
  GIBAKE_TRY(vk.create_buffer(sizeof(table), faces, "LPV face table"));
  GIBAKE_TRY(vk.create_buffer(geometry ? corners * 16 : 16, geo, "LPV geometry volume"));
  GIBAKE_TRY(vk.upload(a, cells.data(), cell_bytes));
  GIBAKE_TRY(vk.upload(acc, cells.data(), cell_bytes));
  GIBAKE_TRY(vk.upload(faces, table, sizeof(table)));
  if (geometry) GIBAKE_TRY(vk.upload(geo, geometry, corners * 16));
  vk::Pipeline scale_pipe, prop_pipe;
  GIBAKE_TRY(vk.create_pipeline(shaders::lpv_scale_spv, sizeof(shaders::lpv_scale_spv) / 4, 3, sizeof(gpu::LpvPush),
                                scale_pipe, "lpv_scale"));
  GIBAKE_TRY(vk.create_pipeline(shaders::lpv_propagate_spv, sizeof(shaders::lpv_propagate_spv) / 4, 6,
                                sizeof(gpu::LpvPush), prop_pipe, "lpv_propagate"));
  // Every step in one submission: scale(src), propagate(src -> dst, acc += dst), swap.
  std::vector<vk::Dispatch> steps;
  const uint32_t groups = uint32_t((n + 63) / 64);
  const vk::Buffer* src = &a;
  const vk::Buffer* dst = &b;
  for (int it = 1; it <= iterations; ++it) {
    gpu::LpvPush push{{uint32_t(grid.dims[0]), uint32_t(grid.dims[1]), uint32_t(grid.dims[2]), 0u}};
    vk::Dispatch s;
    s.pipeline = &scale_pipe;
    s.buffers = {src, &faces, &scale};
    s.push = vk::push_bytes(push);
    s.flat_groups = groups;
    // LPV rule: no occlusion on the first step (the light is injected beside its own surface).
    push.dims.w = (it >= 2 && geometry) ? 1u : 0u;
    vk::Dispatch p;
    p.pipeline = &prop_pipe;
    p.buffers = {src, &scale, &faces, &geo, dst, &acc};
    p.push = vk::push_bytes(push);
    p.flat_groups = groups;
    steps.push_back(s);
    steps.push_back(p);
    std::swap(src, dst);
  }
  GIBAKE_TRY(vk.run(steps));
  accumulated.resize(n);
  return vk.download(acc, accumulated.data(), cell_bytes);
}

namespace {

class VulkanLpvDevice final : public LpvDevice {
 public:
  VulkanLpvDevice(vk::Context& vk, std::unique_ptr<vk::Context> own) : own_(std::move(own)), vk_(vk) {}
  Status propagate(const kernels::LpvGrid& grid, std::vector<kernels::LpvCell> cells, const float* geometry,
                   int iterations, const Context&, std::vector<kernels::LpvCell>& accumulated) override {
    return lpv_propagate_volume_gpu(vk_, grid, cells, geometry, iterations, accumulated);
  }

 private:
  std::unique_ptr<vk::Context> own_;  // null when the context is shared
  vk::Context& vk_;
};

}  // namespace

std::unique_ptr<LpvDevice> make_vulkan_lpv_device(vk::Context& vk, std::unique_ptr<vk::Context> own) {
  return std::make_unique<VulkanLpvDevice>(vk, std::move(own));
}

}  // namespace gibake
