#include "bake/scene/prepare.h"

#include <embree3/rtcore.h>
#include <tbb/task_arena.h>

#include <string>
#include <vector>

#include "bake/scene/material.h"

namespace gibake {
using kernels::float3;

namespace {

struct GeometryData {
  const Scene* scene = nullptr;
  float blend_cutoff = kDefaultBlendCutoff;
  std::vector<TriangleShading> shading;  // Embree primID -> the triangle's packed record (its index too)
};

void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* data = static_cast<const GeometryData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    const TriangleShading& tri = data->shading[prim];
    const float cutoff = alpha_cutoff_of(triangle_material(*data->scene, tri), data->blend_cutoff);
    if (cutoff >= 0.f && surface_alpha(*data->scene, tri, u, v) < cutoff) args->valid[i] = 0;
  }
}

// Squared distance from p to the triangle abc: the closest point is a vertex, a point on an edge or
// one inside, told apart by p's barycentric regions (Ericson, Real-Time Collision Detection 5.1.5).
float triangle_distance2(const float3& p, const float3& a, const float3& b, const float3& c) {
  using kernels::dot;
  const float3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto d2_to = [&](const float3& q) { return dot(p - q, p - q); };
  if (d1 <= 0.f && d2 <= 0.f) return d2_to(a);
  const float3 bp = p - b;
  const float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.f && d4 <= d3) return d2_to(b);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) return d2_to(a + ab * (d1 / (d1 - d3)));
  const float3 cp = p - c;
  const float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.f && d5 <= d6) return d2_to(c);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) return d2_to(a + ac * (d2 / (d2 - d6)));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && d4 - d3 >= 0.f && d5 - d6 >= 0.f) return d2_to(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const float denom = 1.f / (va + vb + vc);
  return d2_to(a + ab * (vb * denom) + ac * (vc * denom));
}

struct SurfaceQuery {
  const GeometryData* geometries = nullptr;
  bool found = false;
};

// A triangle within the query's radius ends the query (its radius set to 0).
bool surface_query_hit(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<SurfaceQuery*>(args->userPtr);
  const GeometryData& g = q->geometries[args->geomID];
  const Scene& scene = *g.scene;
  const uint32_t* idx = g.shading[args->primID].vertex;
  auto vertex = [&](uint32_t i) {
    return float3{scene.positions[size_t(i) * 3], scene.positions[size_t(i) * 3 + 1],
                  scene.positions[size_t(i) * 3 + 2]};
  };
  RTCPointQuery* query = args->query;
  const float3 p{query->x, query->y, query->z};
  if (!(triangle_distance2(p, vertex(idx[0]), vertex(idx[1]), vertex(idx[2])) <= query->radius * query->radius))
    return false;
  q->found = true;
  query->radius = 0.f;
  return true;
}

}  // namespace

struct PreparedScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  GeometryData geometries[2];  // 0: opaque, 1: alpha-masked
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

PreparedScene::PreparedScene(const Scene& scene) : scene_(scene), impl_(std::make_unique<Impl>()) {}
PreparedScene::~PreparedScene() = default;

void* PreparedScene::rtc_scene() const { return impl_->scene; }

Status PreparedScene::create(const Scene& scene, const Context& ctx, std::unique_ptr<PreparedScene>& out,
                             const PrepareOptions& options) {
  std::unique_ptr<PreparedScene> p;
  GIBAKE_TRY(create_unbuilt(scene, p, options));
  // The BVH build runs on TBB: inside an arena of ctx.threads so --threads bounds it too.
  Status built;
  if (ctx.threads > 0) {
    tbb::task_arena arena(static_cast<int>(ctx.threads));
    arena.execute([&] { built = p->build(); });
  } else {
    built = p->build();
  }
  GIBAKE_TRY(built);
  ctx.report("prepare", 1, 1);
  out = std::move(p);
  return Status::ok();
}

Status PreparedScene::create_unbuilt(const Scene& scene, std::unique_ptr<PreparedScene>& out,
                                     const PrepareOptions& options) {
  std::unique_ptr<PreparedScene> p(new PreparedScene(scene));
  Impl& im = *p->impl_;
  im.device = rtcNewDevice(nullptr);
  if (!im.device)
    return Status::error(ExitCode::RuntimeFailure, scene.source_path, "embree", "rtcNewDevice failed");
  im.scene = rtcNewScene(im.device);
  rtcSetSceneFlags(im.scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(im.scene, RTC_BUILD_QUALITY_HIGH);

  const size_t vcount = scene.vertex_count();
  const size_t tcount = scene.triangle_count();
  for (size_t t = 0; t < tcount; ++t) {
    const uint32_t* idx = &scene.indices[t * 3];
    if (idx[0] >= vcount || idx[1] >= vcount || idx[2] >= vcount)
      return Status::invalid(scene.source_path, "triangle " + std::to_string(t), "vertex index out of range");
    const Material& material = triangle_material(scene, static_cast<uint32_t>(t));
    const bool masked = alpha_cutoff_of(material, options.blend_cutoff) >= 0.f;
    if (material.transmission > 0.f) p->has_transmission_ = true;
    im.geometries[masked ? 1 : 0].shading.push_back(triangle_shading(scene, static_cast<uint32_t>(t)));
  }
  p->masked_triangles_ = im.geometries[1].shading.size();
  p->blend_cutoff_ = options.blend_cutoff;

  for (int g = 0; g < 2; ++g) {
    GeometryData& data = im.geometries[g];
    data.scene = &scene;
    data.blend_cutoff = options.blend_cutoff;
    if (data.shading.empty()) continue;
    RTCGeometry geom = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vcount));
    auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(uint32_t), data.shading.size()));
    if (!vb || !ib) {
      rtcReleaseGeometry(geom);
      return Status::error(ExitCode::RuntimeFailure, scene.source_path, "embree", "out of memory for geometry buffers");
    }
    std::copy(scene.positions.begin(), scene.positions.begin() + vcount * 3, vb);
    for (size_t i = 0; i < data.shading.size(); ++i)
      for (int k = 0; k < 3; ++k) ib[i * 3 + k] = data.shading[i].vertex[k];
    if (g == 1) {
      rtcSetGeometryUserData(geom, &data);
      rtcSetGeometryIntersectFilterFunction(geom, alpha_filter);
      rtcSetGeometryOccludedFilterFunction(geom, alpha_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(im.scene, geom, static_cast<unsigned>(g));
    rtcReleaseGeometry(geom);
  }
  out = std::move(p);
  return Status::ok();
}

Status PreparedScene::build() {
  // In the calling thread's arena: its size bounds the build's threads.
  rtcCommitScene(impl_->scene);
  const RTCError err = rtcGetDeviceError(impl_->device);
  if (err != RTC_ERROR_NONE)
    return Status::error(ExitCode::RuntimeFailure, scene_.source_path, "embree",
                         "scene build failed (error " + std::to_string(static_cast<int>(err)) + ")");
  return Status::ok();
}

TraceHit PreparedScene::intersect(const float3& org, const float3& dir, float tnear, float tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = org.x; rh.ray.org_y = org.y; rh.ray.org_z = org.z;
  rh.ray.dir_x = dir.x; rh.ray.dir_y = dir.y; rh.ray.dir_z = dir.z;
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.time = 0.f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  TraceHit h;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
  h.t = rh.ray.tfar;
  h.shading = &impl_->geometries[rh.hit.geomID].shading[rh.hit.primID];
  // A record spans two cache lines at most; asking for both before reading the first overlaps
  // their loads (a hint: no value depends on it).
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(reinterpret_cast<const char*>(h.shading) + sizeof(TriangleShading) - 1);
#endif
  h.triangle = h.shading->triangle;
  h.u = rh.hit.u;
  h.v = rh.hit.v;
  const float3 ng_embree{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
  h.front = is_front_face_embree(dir, ng_embree);
  h.ng = kernels::normalize(ng_embree);
  return h;
}

bool PreparedScene::occluded(const float3& org, const float3& dir, float tnear, float tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = org.x; ray.org_y = org.y; ray.org_z = org.z;
  ray.dir_x = dir.x; ray.dir_y = dir.y; ray.dir_z = dir.z;
  ray.tnear = tnear;
  ray.tfar = tfar;
  ray.time = 0.f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0.f;  // Embree sets tfar = -inf on a hit
}

bool PreparedScene::surface_within(const float3& p, float radius) const {
  RTCPointQuery query;
  query.x = p.x;
  query.y = p.y;
  query.z = p.z;
  query.time = 0.f;
  query.radius = radius;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  SurfaceQuery q{impl_->geometries, false};
  rtcPointQuery(impl_->scene, &query, &context, surface_query_hit, &q);
  return q.found;
}

}  // namespace gibake
