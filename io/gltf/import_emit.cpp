// Places a decoded primitive into the Scene in world space.
#include "io/gltf/gltf_emit.h"

#include <cmath>

namespace gibake::gltf {
namespace {

void transform_point(const Mat4& m, const float* p, float* out) {
  for (int r = 0; r < 3; ++r) {
    double v = m[size_t(r)] * p[0] + m[size_t(4 + r)] * p[1] + m[size_t(8 + r)] * p[2] + m[size_t(12 + r)];
    out[r] = to_float(v);
  }
}

void transform_normal(const std::array<double, 9>& n, const float* v, float* out) {
  double r[3];
  for (int i = 0; i < 3; ++i) r[i] = n[size_t(i * 3)] * v[0] + n[size_t(i * 3 + 1)] * v[1] + n[size_t(i * 3 + 2)] * v[2];
  double l = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  if (!(l > 1e-30) || !std::isfinite(l)) {
    out[0] = 0.f, out[1] = 0.f, out[2] = 1.f;
    return;
  }
  for (int i = 0; i < 3; ++i) out[i] = float(r[i] / l);
}

Status check_caps(const ImportEnv& env, const std::string& where, const PrimitiveData& d, const Scene& scene) {
  uint64_t tris = uint64_t(scene.triangle_count()) + d.indices.size() / 3;
  if (tris > env.limits().max_triangles)
    return env.invalid(where, "scene exceeds the triangle limit of " + std::to_string(env.limits().max_triangles));
  if (uint64_t(scene.vertex_count()) + d.vertex_count() > uint64_t(UINT32_MAX))
    return env.invalid(where, "scene exceeds 2^32 vertices");
  return Status::ok();
}

Status append_vertices(const ImportEnv& env, const std::string& where, const Mat4& world,
                       const std::array<double, 9>& nm, const PrimitiveData& d, Scene& s) {
  size_t n = d.vertex_count(), base = s.positions.size();
  s.positions.resize(base + 3 * n);
  s.normals.resize(base + 3 * n);
  for (size_t i = 0; i < n; ++i) {
    float* p = &s.positions[base + 3 * i];
    transform_point(world, &d.positions[3 * i], p);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      return env.invalid(where, "world-space position is not finite");
    GIBAKE_TRY(env.check_coordinates(where, "world-space position", p));
    s.bounds.extend({p[0], p[1], p[2]});
    transform_normal(nm, &d.normals[3 * i], &s.normals[base + 3 * i]);
  }
  if (d.uvs.size() == 2 * n) s.uvs.insert(s.uvs.end(), d.uvs.begin(), d.uvs.end());
  else s.uvs.resize(s.uvs.size() + 2 * n, 0.f);
  if (d.colors.size() == 4 * n) s.colors.insert(s.colors.end(), d.colors.begin(), d.colors.end());
  else s.colors.resize(s.colors.size() + 4 * n, 1.f);
  return Status::ok();
}

}  // namespace

Status emit_instance(const ImportEnv& env, const NodeInstance& ni, size_t mesh, size_t prim,
                     const PrimitiveData& d, Scene& scene) {
  std::string where = at("nodes", size_t(ni.node));
  std::array<double, 9> nm{};
  if (!mat_normal_matrix(ni.world, nm)) return env.invalid(where, "world matrix of a mesh node is not invertible");
  GIBAKE_TRY(check_caps(env, where, d, scene));
  PrimitiveInstance inst;
  inst.first_triangle = uint32_t(scene.triangle_count());
  inst.triangle_count = uint32_t(d.indices.size() / 3);
  inst.mesh = int(mesh);
  inst.primitive = int(prim);
  inst.node = ni.node;
  inst.draco = d.draco;
  inst.mirrored = mat_det3(ni.world) < 0.0;
  uint32_t base = uint32_t(scene.vertex_count());
  GIBAKE_TRY(append_vertices(env, where, ni.world, nm, d, scene));
  for (size_t t = 0; t + 2 < d.indices.size(); t += 3) {
    uint32_t a = d.indices[t], b = d.indices[t + 1], c = d.indices[t + 2];
    if (inst.mirrored) std::swap(b, c);
    scene.indices.insert(scene.indices.end(), {base + a, base + b, base + c});
    scene.tri_material.push_back(d.material);
  }
  scene.instances.push_back(inst);
  return Status::ok();
}

}  // namespace gibake::gltf
