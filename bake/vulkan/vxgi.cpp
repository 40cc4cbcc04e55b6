#include "bake/vulkan/vxgi.h"

#include <string>

#include "kernels/shaders/gpu_types.h"
#include "kernels/shaders/vxgi_diffuse_spv.h"

namespace gibake {

Status vxgi_diffuse_gpu(vk::Context& vk, const loader::VxgiVolume& v, const std::vector<loader::Vec3>& points,
                        const std::vector<loader::Vec3>& normals, std::vector<loader::Rgb>& out) {
  if (points.size() != normals.size() || points.empty())
    return Status::error(ExitCode::RuntimeFailure, "", "vxgi", "points and normals differ in count or are empty");
  const gibake_vxgi_volume& d = v.desc();
  std::vector<float> radiance;  // the file's layout as float RGBA (the loader converts f16)
  radiance.reserve(size_t(loader::vxgi_radiance_count(d)) * 4);
  for (uint32_t l = 0; l < d.levels; ++l) {
    const std::array<int32_t, 3> ld = v.level_dims(l);
    for (uint32_t f = 0; f < 6; ++f)
      for (int32_t z = 0; z < ld[2]; ++z)
        for (int32_t y = 0; y < ld[1]; ++y)
          for (int32_t x = 0; x < ld[0]; ++x) {
            const loader::Rgba t = v.texel(l, f, x, y, z);
            radiance.insert(radiance.end(), t.begin(), t.end());
          }
  }
  gpu::GpuVxgiParams params{{d.grid_min[0], d.grid_min[1], d.grid_min[2], d.voxel_size},
                            {uint32_t(d.dims[0]), uint32_t(d.dims[1]), uint32_t(d.dims[2]), d.levels},
                            {d.sky[0], d.sky[1], d.sky[2], d.diffuse_scale},
                            {0u, 0u, 0u, 0u}};
  std::vector<gpu::vec4> query(points.size() * 2);
  for (size_t i = 0; i < points.size(); ++i) {
    query[2 * i] = {points[i][0], points[i][1], points[i][2], 0.f};
    query[2 * i + 1] = {normals[i][0], normals[i][1], normals[i][2], 0.f};
  }
  const uint64_t need = radiance.size() * 4 + query.size() * 16 + points.size() * 16 + sizeof params;
  if (need > vk.device().device_memory)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         "voxel GI queries need " + std::to_string(need) + " bytes of device memory; " + vk.device().name +
                             " has " + std::to_string(vk.device().device_memory));
  vk::Buffer pb, rb, qb, ob;
  GIBAKE_TRY(vk.create_buffer(sizeof params, pb, "VXGI parameters"));
  GIBAKE_TRY(vk.create_buffer(radiance.size() * 4, rb, "VXGI radiance"));
  GIBAKE_TRY(vk.create_buffer(query.size() * 16, qb, "VXGI query points"));
  GIBAKE_TRY(vk.create_buffer(points.size() * 16, ob, "VXGI irradiance"));
  GIBAKE_TRY(vk.upload(pb, &params, sizeof params));
  GIBAKE_TRY(vk.upload(rb, radiance.data(), radiance.size() * 4));
  GIBAKE_TRY(vk.upload(qb, query.data(), query.size() * 16));
  vk::Pipeline pipe;
  const gpu::uvec4 push{uint32_t(points.size()), 0u, 0u, 0u};
  GIBAKE_TRY(vk.create_pipeline(shaders::vxgi_diffuse_spv, sizeof(shaders::vxgi_diffuse_spv) / 4, 4, sizeof push, pipe,
                                "vxgi_diffuse"));
  vk::Dispatch dispatch;
  dispatch.pipeline = &pipe;
  dispatch.buffers = {&pb, &rb, &qb, &ob};
  dispatch.push = vk::push_bytes(push);
  dispatch.groups[0] = uint32_t((points.size() + 63) / 64);
  GIBAKE_TRY(vk.run({dispatch}));
  std::vector<gpu::vec4> result(points.size());
  GIBAKE_TRY(vk.download(ob, result.data(), result.size() * 16));
  out.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) out[i] = {result[i].x, result[i].y, result[i].z};
  return Status::ok();
}

}  // namespace gibake
