#include "bake/vulkan/geometry.h"

#include <algorithm>
#include <cstring>

namespace gibake {
using kernels::float3;

namespace {
float3 triangle_normal(const Scene& scene, uint32_t tri) {
  const uint32_t* idx = &scene.indices[size_t(tri) * 3];
  const float3 v0 = kernels::load3(&scene.positions[size_t(idx[0]) * 3]);
  const float3 v1 = kernels::load3(&scene.positions[size_t(idx[1]) * 3]);
  const float3 v2 = kernels::load3(&scene.positions[size_t(idx[2]) * 3]);
  return kernels::cross(v1 - v0, v2 - v0);  // the counter-clockwise side, as Embree's Ng
}
}  // namespace

kernels::HitRecord geometry_record(const Scene& scene, const float3& dir, const gpu::GpuHit& hit,
                                   TraceCounters& counters) {
  kernels::HitRecord rec;
  kernels::store3(rec.dir_t, dir);
  ++counters.rays;
  if (hit.t_tri_uv.x < 0.f) {
    rec.dir_t[3] = -1.f;
    rec.normal_kind[3] = kernels::kHitMiss;
    return rec;
  }
  uint32_t tri;
  std::memcpy(&tri, &hit.t_tri_uv.y, 4);
  const float t = hit.t_tri_uv.x;
  rec.dir_t[3] = t;
  const float3 ng_ccw = triangle_normal(scene, tri);
  const float3 ng = kernels::normalize(ng_ccw);
  const bool front = kernels::dot(dir, ng_ccw) < 0.f;
  const int32_t m = tri < scene.tri_material.size() ? scene.tri_material[tri] : -1;
  const bool double_sided = m >= 0 && size_t(m) < scene.materials.size() && scene.materials[size_t(m)].double_sided;
  if (!front && !double_sided) {
    rec.normal_kind[3] = kernels::kHitBack;
    kernels::store3(rec.normal_kind, -ng);
    ++counters.back_faces;
    return rec;
  }
  rec.normal_kind[3] = kernels::kHitFront;
  if (counters.nearest_front < 0.f || t < counters.nearest_front) counters.nearest_front = t;
  kernels::store3(rec.normal_kind, front ? ng : -ng);
  return rec;
}

Status trace_geometry_gpu(GpuTracer& tracer, const Scene& scene, const std::vector<int32_t>& probes,
                          const GeometryRays& g, uint64_t chunk_rays) {
  const uint32_t n = g.rays_per_probe;
  if (n == 0) return Status::ok();
  const size_t chunk = std::max<size_t>(1, size_t(chunk_rays / n));
  std::vector<gpu::GpuRay> rays;
  std::vector<gpu::GpuHit> hits;
  std::vector<float> dirs(size_t(n) * 3);
  std::vector<kernels::HitRecord> records(n);
  for (size_t first = 0; first < probes.size(); first += chunk) {
    const size_t count = std::min(chunk, probes.size() - first);
    rays.resize(count * n);
    for (size_t i = 0; i < count; ++i) {
      const int32_t p = probes[first + i];
      const float3 o = g.origin(p);
      g.directions(p, dirs.data());
      for (uint32_t r = 0; r < n; ++r)
        rays[i * n + r] = {{o.x, o.y, o.z, 0.f}, {dirs[r * 3], dirs[r * 3 + 1], dirs[r * 3 + 2], INFINITY}};
    }
    GIBAKE_TRY(tracer.intersect(rays, hits));
    for (size_t i = 0; i < count; ++i) {
      const int32_t p = probes[first + i];
      TraceCounters tc;
      for (uint32_t r = 0; r < n; ++r) {
        const gpu::GpuRay& ray = rays[i * n + r];
        const float3 d{ray.dir_tmax.x, ray.dir_tmax.y, ray.dir_tmax.z};
        records[r] = geometry_record(scene, d, hits[i * n + r], tc);
        if (g.capture)
          (*g.capture)[size_t(p)].push_back(CapturedRay{{ray.org_tmin.x, ray.org_tmin.y, ray.org_tmin.z},
                                                        {d.x, d.y, d.z}, 0.f, INFINITY, CapturedRay::kRelocation});
      }
      g.done(p, records.data(), tc);
    }
  }
  return Status::ok();
}

}  // namespace gibake
