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

// Runs the query kernel in `mode` (0: the 6 diffuse cones, 1: the 16 precomputed cone directions,
// 2: the specular cone) over `query` (`stride` vec4s a point) and returns one vec4 a point.
Status run_queries(vk::Context& vk, const loader::VxgiClipmaps& c, const std::vector<gpu::vec4>& query, uint32_t stride,
                   uint32_t mode, bool use_sdf, std::vector<gpu::vec4>& result) {
  const size_t count = query.size() / stride;
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
  const uint64_t need = radiance.size() * 4 + sdf.size() * 4 + query.size() * 16 + count * 16 +
                        params.size() * sizeof(gpu::GpuVxgiParams);
  GIBAKE_TRY(vk.check_device_memory(need, 0, "voxel GI queries",
                                     "a smaller --vxgi-res lowers it; --backend cpu bakes without the device"));
  vk::Buffer pb, rb, qb, ob, sb;
  GIBAKE_TRY(vk.create_buffer(params.size() * sizeof(gpu::GpuVxgiParams), pb, "VXGI parameters"));
  GIBAKE_TRY(vk.create_buffer(radiance.size() * 4, rb, "VXGI radiance"));
  GIBAKE_TRY(vk.create_buffer(query.size() * 16, qb, "VXGI query points"));
  GIBAKE_TRY(vk.create_buffer(count * 16, ob, "VXGI results"));
  GIBAKE_TRY(vk.create_buffer(sdf.size() * 4, sb, "VXGI SDF"));
  GIBAKE_TRY(vk.upload(sb, sdf.data(), sdf.size() * 4));
  GIBAKE_TRY(vk.upload(pb, params.data(), params.size() * sizeof(gpu::GpuVxgiParams)));
  GIBAKE_TRY(vk.upload(rb, radiance.data(), radiance.size() * 4));
  GIBAKE_TRY(vk.upload(qb, query.data(), query.size() * 16));
  vk::Pipeline pipe;
  const gpu::uvec4 push{uint32_t(count), use_sdf ? 1u : 0u, uint32_t(c.count), mode};
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
  const uint32_t groups = serial ? uint32_t(count) : uint32_t((count + 63) / 64);
  dispatch.flat_groups = groups;  // folded into rows within the device's maxComputeWorkGroupCount
  GIBAKE_TRY(vk.run({dispatch}));
  result.resize(count);
  return vk.download(ob, result.data(), result.size() * 16);
}

}  // namespace

Status vxgi_diffuse_gpu(vk::Context& vk, const loader::VxgiClipmaps& c, const std::vector<loader::Vec3>& points,
                        const std::vector<loader::Vec3>& normals, std::vector<loader::Rgb>& out, bool use_sdf,
                        bool precomputed_cones) {
  if (points.size() != normals.size() || points.empty() || c.count == 0)
    return Status::error(ExitCode::RuntimeFailure, "", "vxgi",
                         "points and normals differ in count, or nothing to trace");
  std::vector<gpu::vec4> query(points.size() * 2), result;
  for (size_t i = 0; i < points.size(); ++i) {
    query[2 * i] = {points[i][0], points[i][1], points[i][2], 0.f};
    query[2 * i + 1] = {normals[i][0], normals[i][1], normals[i][2], 0.f};
  }
  GIBAKE_TRY(run_queries(vk, c, query, 2, precomputed_cones ? 1u : 0u, use_sdf, result));
  out.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) out[i] = {result[i].x, result[i].y, result[i].z};
  return Status::ok();
}

Status vxgi_specular_gpu(vk::Context& vk, const loader::VxgiClipmaps& c, const std::vector<SpecularQuery>& queries,
                         std::vector<loader::Rgba>& out, bool use_sdf) {
  if (queries.empty() || c.count == 0) return Status::error(ExitCode::RuntimeFailure, "", "vxgi", "nothing to trace");
  std::vector<gpu::vec4> query(queries.size() * 3), result;
  for (size_t i = 0; i < queries.size(); ++i) {
    const SpecularQuery& q = queries[i];
    query[3 * i] = {q.point[0], q.point[1], q.point[2], q.roughness};
    query[3 * i + 1] = {q.normal[0], q.normal[1], q.normal[2], 0.f};
    query[3 * i + 2] = {q.to_eye[0], q.to_eye[1], q.to_eye[2], 0.f};
  }
  GIBAKE_TRY(run_queries(vk, c, query, 3, 2u, use_sdf, result));
  out.resize(queries.size());
  for (size_t i = 0; i < queries.size(); ++i) out[i] = {result[i].x, result[i].y, result[i].z, result[i].w};
  return Status::ok();
}

}  // namespace gibake
