// Scene preparation for CPU tracing: one Embree device and scene built from Scene triangles.
// Opaque triangles go into one geometry; alpha-masked ones (MASK, and BLEND treated as MASK with
// cutoff PrepareOptions::blend_cutoff) into a second geometry whose intersection and occlusion filter functions sample
// base-colour alpha at the hit against the cutoff. Embree stays private to this file's .cpp.
#pragma once
#include <cstdint>
#include <memory>

#include "bake/scene/material.h"
#include "bake/scene/triangle_shading.h"
#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"
#include "kernels/vec.h"

namespace gibake {

struct TraceHit {
  float t = -1.f;         // < 0: miss
  uint32_t triangle = 0;  // index into Scene triangles
  float u = 0.f, v = 0.f; // Embree barycentrics
  bool front = false;     // the ray met the counter-clockwise (front) side
  kernels::float3 ng;     // unit geometric normal of the CCW (front) side
  const TriangleShading* shading = nullptr;  // the triangle's packed record (set on a hit)
};

struct PrepareOptions {
  float blend_cutoff = kDefaultBlendCutoff;  // alphaMode BLEND traced as MASK with this cutoff; <= 0: opaque
};

class PreparedScene {
 public:
  ~PreparedScene();
  PreparedScene(const PreparedScene&) = delete;
  PreparedScene& operator=(const PreparedScene&) = delete;

  // Builds the Embree scene. The Scene must outlive the PreparedScene.
  static Status create(const Scene& scene, const Context& ctx, std::unique_ptr<PreparedScene>& out,
                       const PrepareOptions& options = {});
  // create() in two steps, so the BVH build can run as a task beside other stages: the device and
  // geometries here (call it outside any TBB arena: Embree's scheduler set-up would take that
  // arena's size for the rest of the process), then build() in the arena that should run it,
  // before any trace.
  static Status create_unbuilt(const Scene& scene, std::unique_ptr<PreparedScene>& out,
                               const PrepareOptions& options = {});
  Status build();

  // Closest hit along org + t*dir, t in [tnear, tfar]. Thread-safe.
  TraceHit intersect(const kernels::float3& org, const kernels::float3& dir, float tnear, float tfar) const;
  // Any hit in [tnear, tfar]. Thread-safe.
  bool occluded(const kernels::float3& org, const kernels::float3& dir, float tnear, float tfar) const;
  // Whether some triangle comes within `radius` of p, either face, a masked one wherever its mask
  // lets light through too (a point query sees the triangle, not its texture). Thread-safe.
  bool surface_within(const kernels::float3& p, float radius) const;

  const Scene& scene() const { return scene_; }
  size_t masked_triangles() const { return masked_triangles_; }
  // Cutoff BLEND materials are traced with (PrepareOptions::blend_cutoff).
  float blend_cutoff() const { return blend_cutoff_; }
  // Whether any triangle's material transmits (Material::transmission > 0): only then do shadow
  // rays look past the first surface (bake/trace/probe_rays.h transmittance).
  bool has_transmission() const { return has_transmission_; }
  // The RTCScene (as void*) for benchmarks that trace it directly.
  void* rtc_scene() const;

 private:
  explicit PreparedScene(const Scene& scene);
  struct Impl;
  const Scene& scene_;
  std::unique_ptr<Impl> impl_;
  size_t masked_triangles_ = 0;
  float blend_cutoff_ = 0.5f;
  bool has_transmission_ = false;
};

// The surface at a hit (t >= 0, from PreparedScene::intersect) and its material, read from the
// hit's packed record.
inline SurfaceSample hit_surface(const Scene& scene, const TraceHit& hit, const TextureFootprint& footprint) {
  return surface_sample(scene, *hit.shading, hit.u, hit.v, footprint);
}
// hit_surface in two steps (bake/scene/material.h PendingSurface).
inline PendingSurface begin_hit_surface(const Scene& scene, const TraceHit& hit, const TextureFootprint& footprint) {
  return begin_surface_sample(scene, *hit.shading, hit.u, hit.v, footprint);
}
inline const Material& hit_material(const Scene& scene, const TraceHit& hit) {
  return triangle_material(scene, *hit.shading);
}

// Embree 3.13's reported geometric normal Ng points to the counter-clockwise side, i.e. it has
// the direction of cross(v1-v0, v2-v0) (checked by tests/bake EmbreeFaces.GeometricNormalSign:
// triangle (0,0,0),(1,0,0),(0,1,0) reports Ng = +z). A hit is front-facing iff
// dot(dir, Ng_ccw) < 0, i.e. dot(dir, Ng_embree) < 0.
inline bool is_front_face_embree(const kernels::float3& dir, const kernels::float3& ng_embree) {
  return kernels::dot(dir, ng_embree) < 0.f;
}

}  // namespace gibake
