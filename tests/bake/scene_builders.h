// Scenes built in code for the baker tests (no importer).
#pragma once
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

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

// Icosphere: an icosahedron split `levels` times, each corner one shared vertex (the index buffer
// joins the triangles, so neighbours meet on bit-identical edges: a closed, watertight mesh).
// Outward normals, CCW from outside.
inline void add_icosphere(Scene& s, const Vec3f& c, float r, int levels, int material) {
  const float t = (1.f + std::sqrt(5.f)) / 2.f;
  std::vector<Vec3f> dirs = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                             {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  // The icosahedron's 20 faces, five to a row.
  // clang-format off
  std::vector<uint32_t> tris = {0, 11, 5,   0, 5, 1,    0, 1, 7,    0, 7, 10,   0, 10, 11,
                                1, 5, 9,    5, 11, 4,   11, 10, 2,  10, 7, 6,   7, 1, 8,
                                3, 9, 4,    3, 4, 2,    3, 2, 6,    3, 6, 8,    3, 8, 9,
                                4, 9, 5,    2, 4, 11,   6, 2, 10,   8, 6, 7,    9, 8, 1};
  // clang-format on
  auto unit = [](Vec3f d) {
    const float l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    return Vec3f{d[0] / l, d[1] / l, d[2] / l};
  };
  for (Vec3f& d : dirs) d = unit(d);
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      const auto found = middle.find(key);
      if (found != middle.end()) return found->second;
      dirs.push_back(unit({dirs[a][0] + dirs[b][0], dirs[a][1] + dirs[b][1], dirs[a][2] + dirs[b][2]}));
      return middle[key] = uint32_t(dirs.size() - 1);
    };
    std::vector<uint32_t> split;
    for (size_t i = 0; i < tris.size(); i += 3) {
      const uint32_t a = tris[i], b = tris[i + 1], d = tris[i + 2];
      const uint32_t ab = mid(a, b), bd = mid(b, d), da = mid(d, a);
      split.insert(split.end(), {a, ab, da, b, bd, ab, d, da, bd, ab, bd, da});
    }
    tris.swap(split);
  }
  const uint32_t first = uint32_t(s.vertex_count());
  for (const Vec3f& d : dirs) add_vertex(s, {c[0] + r * d[0], c[1] + r * d[1], c[2] + r * d[2]}, d);
  for (size_t i = 0; i < tris.size(); i += 3) {
    s.indices.insert(s.indices.end(), {first + tris[i], first + tris[i + 1], first + tris[i + 2]});
    s.tri_material.push_back(material);
  }
}

}  // namespace gibake::test
