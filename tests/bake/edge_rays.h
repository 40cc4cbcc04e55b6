// Rays that test a tracer's watertightness: from points inside a closed mesh towards points on its
// triangles' shared edges and corners. A watertight triangle test gives every such ray a hit (a
// shared edge belongs to both its triangles); a test that rounds each triangle on its own lets a
// share of them slip between the two, which in a bake is light leaking through a closed wall.
#pragma once
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "io/scene.h"
#include "kernels/vec.h"

namespace gibake::test {

struct EdgeRay {
  kernels::float3 org, dir;
};

// `n` rays from inside the ball of radius `inner` about `centre` (which the mesh must enclose)
// towards a random triangle's edge at a random fraction along it; with `corner_every` k > 0, every
// k-th ray aims at a corner instead (a point that a whole fan of triangles shares).
inline std::vector<EdgeRay> rays_at_edges(const Scene& s, const Vec3f& centre, float inner, size_t n, uint32_t seed,
                                          size_t corner_every = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  std::uniform_int_distribution<size_t> pick(0, s.triangle_count() - 1);
  std::vector<EdgeRay> rays(n);
  for (size_t i = 0; i < n; ++i) {
    kernels::float3 o;
    do {
      o = {2.f * u01(rng) - 1.f, 2.f * u01(rng) - 1.f, 2.f * u01(rng) - 1.f};
    } while (kernels::dot(o, o) > 1.f);
    o = kernels::float3{centre[0], centre[1], centre[2]} + o * inner;
    const size_t t = pick(rng);
    const int k = int(rng() % 3);
    const float* a = &s.positions[size_t(s.indices[t * 3 + size_t(k)]) * 3];
    const float* b = &s.positions[size_t(s.indices[t * 3 + size_t((k + 1) % 3)]) * 3];
    const float f = corner_every && i % corner_every == corner_every - 1 ? 0.f : u01(rng);
    const kernels::float3 target{a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f};
    rays[i] = {o, kernels::normalize(target - o)};
  }
  return rays;
}

}  // namespace gibake::test
