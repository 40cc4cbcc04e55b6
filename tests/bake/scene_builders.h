// Scenes built in code for the baker tests (no importer).
#pragma once
#include <cmath>

#include "io/scene.h"

namespace gibake::test {

inline int add_material(Scene& s, float albedo, float emission = 0.f, bool double_sided = false) {
  Material m;
  m.base_color[0] = m.base_color[1] = m.base_color[2] = albedo;
  m.emissive[0] = m.emissive[1] = m.emissive[2] = emission > 0.f ? 1.f : 0.f;
  m.emissive_strength = emission;
  m.double_sided = double_sided;
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size()) - 1;
}

inline uint32_t add_vertex(Scene& s, const Vec3f& p, const Vec3f& n) {
  s.positions.insert(s.positions.end(), {p[0], p[1], p[2]});
  s.normals.insert(s.normals.end(), {n[0], n[1], n[2]});
  s.uvs.insert(s.uvs.end(), {0.f, 0.f});
  s.bounds.extend(p);
  return static_cast<uint32_t>(s.vertex_count() - 1);
}

// Triangle whose front (CCW) side faces `n`.
inline void add_triangle(Scene& s, Vec3f a, Vec3f b, Vec3f c, const Vec3f& n, int material) {
  const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const float cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  if (cr[0] * n[0] + cr[1] * n[1] + cr[2] * n[2] < 0.f) std::swap(b, c);
  s.indices.push_back(add_vertex(s, a, n));
  s.indices.push_back(add_vertex(s, b, n));
  s.indices.push_back(add_vertex(s, c, n));
  s.tri_material.push_back(material);
}

inline void add_quad(Scene& s, const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& d, const Vec3f& n,
                     int material) {
  add_triangle(s, a, b, c, n, material);
  add_triangle(s, a, c, d, n, material);
}

// Axis-aligned box [lo, hi]; normals point inwards (a room) or outwards (a solid). Face
// axis*2 + side (side 0 at lo, 1 at hi) is left out where bit (axis*2 + side) of skip_faces is set
// (kSkipBottom: a box without its bottom face).
constexpr unsigned kSkipBottom = 1u << 2;
inline void add_box(Scene& s, const Vec3f& lo, const Vec3f& hi, bool inward, int material, unsigned skip_faces = 0) {
  const float sg = inward ? 1.f : -1.f;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      if (skip_faces & (1u << (axis * 2 + side))) continue;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const float w = side ? hi[axis] : lo[axis];
      Vec3f n{0, 0, 0};
      n[axis] = (side ? -1.f : 1.f) * sg;
      Vec3f p[4];
      const float us[4] = {lo[u], hi[u], hi[u], lo[u]}, vs[4] = {lo[v], lo[v], hi[v], hi[v]};
      for (int k = 0; k < 4; ++k) {
        p[k][axis] = w;
        p[k][u] = us[k];
        p[k][v] = vs[k];
      }
      add_quad(s, p[0], p[1], p[2], p[3], n, material);
    }
}

// A 4 m room of 0.1 m thick solid slabs (floor, ceiling, back and side walls), open at z = 4:
// cornell-box-nvpro's shape. The slabs' front faces at z = 4 look out of the scene.
inline Scene open_front_room(float albedo) {
  Scene s;
  const int m = add_material(s, albedo);
  add_box(s, {-0.1f, -0.1f, -0.1f}, {4.1f, 0.f, 4.f}, false, m);  // floor
  add_box(s, {-0.1f, 4.f, -0.1f}, {4.1f, 4.1f, 4.f}, false, m);   // ceiling
  add_box(s, {-0.1f, 0.f, -0.1f}, {0.f, 4.f, 4.f}, false, m);     // left
  add_box(s, {4.f, 0.f, -0.1f}, {4.1f, 4.f, 4.f}, false, m);      // right
  add_box(s, {0.f, 0.f, -0.1f}, {4.f, 4.f, 0.f}, false, m);       // back
  return s;
}

// UV sphere, outward normals, CCW from outside.
inline void add_sphere(Scene& s, const Vec3f& c, float r, int segments, int rings, int material) {
  auto point = [&](int i, int j, Vec3f& n) {
    const float th = 3.14159265f * j / rings, ph = 2.f * 3.14159265f * i / segments;
    n = {std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
    return Vec3f{c[0] + r * n[0], c[1] + r * n[1], c[2] + r * n[2]};
  };
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      Vec3f n00, n10, n01, n11;
      const Vec3f p00 = point(i, j, n00), p10 = point(i + 1, j, n10), p01 = point(i, j + 1, n01),
                  p11 = point(i + 1, j + 1, n11);
      auto tri = [&](const Vec3f& a, const Vec3f& na, const Vec3f& b, const Vec3f& nb, const Vec3f& d, const Vec3f& nd) {
        const Vec3f fn{na[0] + nb[0] + nd[0], na[1] + nb[1] + nd[1], na[2] + nb[2] + nd[2]};
        // Orient by the outward face normal, then give each vertex its own normal.
        const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
        const float cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        const float area2 = cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2];
        if (area2 < 1e-20f) return;
        const bool flip = cr[0] * fn[0] + cr[1] * fn[1] + cr[2] * fn[2] < 0.f;
        s.indices.push_back(add_vertex(s, a, na));
        s.indices.push_back(flip ? add_vertex(s, d, nd) : add_vertex(s, b, nb));
        s.indices.push_back(flip ? add_vertex(s, b, nb) : add_vertex(s, d, nd));
        s.tri_material.push_back(material);
      };
      tri(p00, n00, p10, n10, p11, n11);
      tri(p00, n00, p11, n11, p01, n01);
    }
}

}  // namespace gibake::test
