#include "bake/vulkan/vxgi.h"

#include <algorithm>
#include <string>

#include "kernels/shaders/gpu_types.h"
#include "kernels/shaders/vxgi_diffuse_serial_spv.h"
#include "kernels/shaders/vxgi_diffuse_spv.h"

namespace gibake {

namespace {

// The file's layout as float RGBA (the loader converts f16), every clipmap after the previous, all
// its faces (6, or 22 with precomputed cone slices).
void flatten(const loader::VxgiVolume& v, std::vector<float>& radiance, std::vector<float>& sdf) {
  const gibake_vxgi_volume& d = v.desc();
  for (uint32_t l = 0; l < d.levels; ++l) {
    const std::array<int32_t, 3> ld = v.level_dims(l);
    for (uint32_t f = 0; f < v.faces(); ++f)
      for (int32_t z = 0; z < ld[2]; ++z)
        for (int32_t y = 0; y < ld[1]; ++y)
          for (int32_t x = 0; x < ld[0]; ++x) {
            const loader::Rgba t = v.texel(l, f, x, y, z);
            radiance.insert(radiance.end(), t.begin(), t.end());
          }
  }
  if (!v.has_sdf()) return;
  for (int32_t z = 0; z < d.dims[2]; ++z)
    for (int32_t y = 0; y < d.dims[1]; ++y)
      for (int32_t x = 0; x < d.dims[0]; ++x) sdf.push_back(v.sdf_texel(x, y, z));
}

}  // namespace

Status vxgi_diffuse_gpu(vk::Context& vk, const loader::VxgiClipmaps& c, const std::vector<loader::Vec3>& points,
                        const std::vector<loader::Vec3>& normals, std::vector<loader::Rgb>& out, bool use_sdf,
                        bool seed_cones) {
  if (points.size() != normals.size() || points.empty() || c.count == 0)
    return Status::error(ExitCode::RuntimeFailure, "", "vxgi", "points and normals differ in count, or nothing to trace");
  std::vector<float> radiance, sdf;
  std::vector<gpu::GpuVxgiParams> params;
  for (size_t k = 0; k < c.count; ++k) {
    const gibake_vxgi_volume& d = c[k].desc();
    params.push_back({{d.grid_min[0], d.grid_min[1], d.grid_min[2], d.voxel_size},
                      {uint32_t(d.dims[0]), uint32_t(d.dims[1]), uint32_t(d.dims[2]), d.levels},
                      {d.sky[0], d.sky[1], d.sky[2], d.diffuse_scale},
                      {c[k].has_sdf() ? 1u : 0u, uint32_t(radiance.size() / 4), uint32_t(sdf.size()), c[k].faces()}});
    flatten(c[k], radiance, sdf);
  }
  if (sdf.empty()) sdf.push_back(0.f);  // a buffer must not be empty
  std::vector<gpu::vec4> query(points.size() * 2);
  for (size_t i = 0; i < points.size(); ++i) {
    query[2 * i] = {points[i][0], points[i][1], points[i][2], 0.f};
    query[2 * i + 1] = {normals[i][0], normals[i][1], normals[i][2], 0.f};
  }
  const uint64_t need = radiance.size() * 4 + sdf.size() * 4 + query.size() * 16 + points.size() * 16 +
                        params.size() * sizeof(gpu::GpuVxgiParams);
  if (need > vk.device().device_memory)
    return Status::error(ExitCode::RuntimeFailure, "", "vulkan",
                         "voxel GI queries need " + std::to_string(need) + " bytes of device memory; " + vk.device().name +
                             " has " + std::to_string(vk.device().device_memory));
  vk::Buffer pb, rb, qb, ob, sb;
  GIBAKE_TRY(vk.create_buffer(params.size() * sizeof(gpu::GpuVxgiParams), pb, "VXGI parameters"));
  GIBAKE_TRY(vk.create_buffer(radiance.size() * 4, rb, "VXGI radiance"));
  GIBAKE_TRY(vk.create_buffer(query.size() * 16, qb, "VXGI query points"));
  GIBAKE_TRY(vk.create_buffer(points.size() * 16, ob, "VXGI irradiance"));
  GIBAKE_TRY(vk.create_buffer(sdf.size() * 4, sb, "VXGI SDF"));
  GIBAKE_TRY(vk.upload(sb, sdf.data(), sdf.size() * 4));
  GIBAKE_TRY(vk.upload(pb, params.data(), params.size() * sizeof(gpu::GpuVxgiParams)));
  GIBAKE_TRY(vk.upload(rb, radiance.data(), radiance.size() * 4));
  GIBAKE_TRY(vk.upload(qb, query.data(), query.size() * 16));
  vk::Pipeline pipe;
  const gpu::uvec4 push{uint32_t(points.size()), use_sdf ? 1u : 0u, uint32_t(c.count), seed_cones ? 1u : 0u};
  // lavapipe gets the one-invocation groups: headroom under its loop cap (vxgi_diffuse_serial.comp).
  const bool serial = vk.device().is_lavapipe();
  if (serial)
    GIBAKE_TRY(vk.create_pipeline(shaders::vxgi_diffuse_serial_spv, sizeof(shaders::vxgi_diffuse_serial_spv) / 4, 5,
                                  sizeof push, pipe, "vxgi_diffuse_serial"));
  else
    GIBAKE_TRY(vk.create_pipeline(shaders::vxgi_diffuse_spv, sizeof(shaders::vxgi_diffuse_spv) / 4, 5, sizeof push, pipe,
                                  "vxgi_diffuse"));
  vk::Dispatch dispatch;
  dispatch.pipeline = &pipe;
  dispatch.buffers = {&pb, &rb, &qb, &ob, &sb};
  dispatch.push = vk::push_bytes(push);
  const uint32_t groups = serial ? uint32_t(points.size()) : uint32_t((points.size() + 63) / 64);
  dispatch.groups[0] = std::min<uint32_t>(groups, 65535u);
  dispatch.groups[1] = (groups + 65534u) / 65535u;
  GIBAKE_TRY(vk.run({dispatch}));
  std::vector<gpu::vec4> result(points.size());
  GIBAKE_TRY(vk.download(ob, result.data(), result.size() * 16));
  out.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) out[i] = {result[i].x, result[i].y, result[i].z};
  return Status::ok();
}

}  // namespace gibake
