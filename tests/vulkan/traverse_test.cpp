// GPU traversal (kernels/shaders/traverse.comp over the rtcBuildBVH layout) against Embree's
// rtcIntersect1 / rtcOccluded1 (bake/scene/prepare.cpp, with its alpha filter) on random rays.
// Closest hit: hit/miss must agree for every ray; t within kRelT x (t + the scene's largest
// coordinate) (both are single precision: the device's watertight test against Embree's robust
// Pluecker test, whose errors scale with the coordinates); the triangle and barycentrics must agree except at
// ties: another triangle that the ray really meets at the same t (checked in double precision),
// e.g. a shared edge or coplanar duplicate faces (Sponza has many). Shadow queries: every answer agrees. Masked triangles may differ only
// where the alpha at the hit lies within kAlphaTie of the cutoff (texture rounding).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "bake/scene/material.h"
#include "bake/scene/prepare.h"
#include "bake/vulkan/device_scene.h"
#include "bake/vulkan/traverse.h"
#include "io/gltf/import.h"
#include "tests/bake/edge_rays.h"
#include "tests/bake/scene_builders.h"
#include "tests/vulkan/gpu_test_scenes.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

constexpr float kRelT = 1e-5f;  // of (t + the scene's largest coordinate): a few float ulps
constexpr float kAlphaTie = 2e-3f;

struct Tally {
  size_t rays = 0, hits = 0, ties = 0, alpha_ties = 0, bad_hit = 0, bad_t = 0, bad_prim = 0;
  size_t shadow = 0, blocked = 0, bad_shadow = 0;
  float max_rel_t = 0.f;
};

std::vector<gpu::GpuRay> random_rays(const Scene& scene, size_t n, uint32_t seed, bool segments) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  auto point = [&] {
    kernels::float3 p;
    float* c[3] = {&p.x, &p.y, &p.z};
    for (int k = 0; k < 3; ++k) {
      const float lo = scene.bounds.min[k], hi = scene.bounds.max[k], pad = 0.05f * (hi - lo);
      *c[k] = lo + pad + u01(rng) * (hi - lo - 2 * pad);
    }
    return p;
  };
  std::vector<gpu::GpuRay> rays(n);
  for (auto& r : rays) {
    const kernels::float3 o = point();
    kernels::float3 d;
    float tmax = INFINITY;
    if (segments) {
      const kernels::float3 to = point() - o;
      tmax = kernels::length(to);
      d = to * (1.f / tmax);
    } else {
      const float z = 2.f * u01(rng) - 1.f, phi = 6.2831853f * u01(rng), s = std::sqrt(std::max(0.f, 1.f - z * z));
      d = {s * std::cos(phi), s * std::sin(phi), z};
    }
    r.org_tmin = {o.x, o.y, o.z, 0.f};
    r.dir_tmax = {d.x, d.y, d.z, tmax};
  }
  return rays;
}

float scene_extent(const Scene& s) {
  float m = 0.f;
  for (int k = 0; k < 3; ++k) m = std::max({m, std::fabs(s.bounds.min[k]), std::fabs(s.bounds.max[k])});
  return m;
}

// Where the ray meets triangle `tri` (double-precision Moller-Trumbore with a 1e-6 barycentric
// slack), or -1.
double exact_t(const Scene& s, uint32_t tri, const gpu::GpuRay& r) {
  double v[3][3];
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) v[k][c] = s.positions[size_t(s.indices[size_t(tri) * 3 + k]) * 3 + c];
  const double o[3] = {r.org_tmin.x, r.org_tmin.y, r.org_tmin.z}, d[3] = {r.dir_tmax.x, r.dir_tmax.y, r.dir_tmax.z};
  double e1[3], e2[3], sv[3];
  for (int c = 0; c < 3; ++c) e1[c] = v[1][c] - v[0][c], e2[c] = v[2][c] - v[0][c], sv[c] = o[c] - v[0][c];
  auto cross = [](const double* a, const double* b, double* out) {
    out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
  };
  auto dot = [](const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  double p[3], q[3];
  cross(d, e2, p);
  const double det = dot(e1, p);
  if (det == 0.0) return -1.0;
  cross(sv, e1, q);
  const double u = dot(sv, p) / det, w = dot(d, q) / det;
  if (u < -1e-6 || w < -1e-6 || u + w > 1.0 + 1e-6) return -1.0;
  return dot(e2, q) / det;
}

bool near_cutoff(const PreparedScene& ps, uint32_t tri, float u, float v) {
  const float cutoff = alpha_cutoff_of(triangle_material(ps.scene(), tri), ps.blend_cutoff());
  return cutoff >= 0.f && std::fabs(surface_alpha(ps.scene(), tri, u, v) - cutoff) < kAlphaTie;
}

Tally compare(vk::Context& vk, const Scene& scene, size_t n_rays, uint32_t seed) {
  Tally tl;
  test::Tracers tr;
  if (!test::make_tracers(vk, scene, tr, 1u << 14)) return tl;
  const PreparedScene* ps = tr.cpu.get();
  GpuTracer* tracer = tr.gpu.get();
  const auto rays = random_rays(scene, n_rays, seed, false);
  const float extent = scene_extent(scene);
  std::vector<gpu::GpuHit> hits;
  EXPECT_TRUE(tracer->intersect(rays, hits));
  for (size_t i = 0; i < rays.size(); ++i) {
    const auto& r = rays[i];
    const kernels::float3 o{r.org_tmin.x, r.org_tmin.y, r.org_tmin.z}, d{r.dir_tmax.x, r.dir_tmax.y, r.dir_tmax.z};
    const TraceHit cpu = ps->intersect(o, d, 0.f, INFINITY);
    const float gt = hits[i].t_tri_uv.x;
    uint32_t gtri;
    std::memcpy(&gtri, &hits[i].t_tri_uv.y, 4);
    ++tl.rays;
    if ((cpu.t < 0.f) != (gt < 0.f)) {
      // A masked triangle whose alpha sits at the cutoff may be kept by one side only.
      const bool tie = cpu.t >= 0.f ? near_cutoff(*ps, cpu.triangle, cpu.u, cpu.v)
                                    : near_cutoff(*ps, gtri, hits[i].t_tri_uv.z, hits[i].t_tri_uv.w);
      tie ? ++tl.alpha_ties : ++tl.bad_hit;
      continue;
    }
    if (cpu.t < 0.f) continue;
    ++tl.hits;
    const float rel = std::fabs(gt - cpu.t) / (cpu.t + extent);
    tl.max_rel_t = std::max(tl.max_rel_t, rel);
    if (rel > kRelT) {
      const bool tie = near_cutoff(*ps, cpu.triangle, cpu.u, cpu.v) ||
                       near_cutoff(*ps, gtri, hits[i].t_tri_uv.z, hits[i].t_tri_uv.w);
      tie ? ++tl.alpha_ties : ++tl.bad_t;
      continue;
    }
    if (gtri != cpu.triangle) {
      // Same distance, another triangle: it must really be there.
      const double te = exact_t(scene, gtri, r);
      te >= 0.0 && std::fabs(te - gt) <= kRelT * (cpu.t + extent) ? ++tl.ties : ++tl.bad_prim;
      continue;
    }
    if (std::fabs(hits[i].t_tri_uv.z - cpu.u) > 1e-3f || std::fabs(hits[i].t_tri_uv.w - cpu.v) > 1e-3f) ++tl.bad_prim;
  }
  const auto segs = random_rays(scene, n_rays, seed + 1, true);
  std::vector<uint32_t> blocked;
  EXPECT_TRUE(tracer->occluded(segs, blocked));
  for (size_t i = 0; i < segs.size(); ++i) {
    const auto& r = segs[i];
    const bool cpu = ps->occluded({r.org_tmin.x, r.org_tmin.y, r.org_tmin.z}, {r.dir_tmax.x, r.dir_tmax.y, r.dir_tmax.z},
                                  0.f, r.dir_tmax.w);
    ++tl.shadow;
    tl.blocked += cpu;
    if (cpu != (blocked[i] != 0)) ++tl.bad_shadow;
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(&vk);
  return tl;
}

void expect_agreement(const Tally& t, const char* what) {
  SCOPED_TRACE(what);
  std::printf("%s: %zu rays, %zu hits, max relative t difference %.2e, %zu ties, %zu alpha ties; %zu shadow rays "
              "(%zu blocked)\n",
              what, t.rays, t.hits, t.max_rel_t, t.ties, t.alpha_ties, t.shadow, t.blocked);
  EXPECT_EQ(t.bad_hit, 0u);
  EXPECT_EQ(t.bad_t, 0u);
  EXPECT_EQ(t.bad_prim, 0u);
  EXPECT_EQ(t.bad_shadow, 0u);
  EXPECT_LE(t.ties, t.hits / 50 + 2);  // coplanar duplicates aside, ties are rare
  EXPECT_LE(t.alpha_ties, t.rays / 1000 + 2);
  EXPECT_GT(t.hits, t.rays / 10);       // the rays meet the scene
  EXPECT_GT(t.blocked, 0u);
  EXPECT_LT(t.blocked, t.shadow);
}

// Random triangles in a unit cube, some masked by a checkerboard texture (alpha 0 or 1 cells,
// vertex-colour alpha, a texture transform on one material, BLEND as MASK).
Scene random_scene(uint32_t seed, size_t count) {
  Scene s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  Texture checker;
  checker.width = checker.height = 8;
  checker.wrap_s = 10497;
  checker.wrap_t = 33648;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) checker.rgba8.insert(checker.rgba8.end(), {200, 100, 50, uint8_t((x + y) % 2 ? 255 : 0)});
  s.textures.push_back(checker);
  s.materials.resize(4);
  s.materials[1].alpha_mode = AlphaMode::Mask;
  s.materials[1].alpha_cutoff = 0.4f;
  s.materials[1].base_color_texture.texture = 0;
  s.materials[2] = s.materials[1];
  s.materials[2].alpha_mode = AlphaMode::Blend;
  s.materials[2].base_color_texture.has_transform = true;
  s.materials[2].base_color_texture.rotation = 0.3f;
  s.materials[2].base_color_texture.scale[0] = 2.f;
  s.materials[2].base_color_texture.offset[1] = 0.25f;
  s.materials[3].alpha_mode = AlphaMode::Mask;  // vertex alpha only
  s.materials[3].base_color[3] = 0.9f;
  for (size_t t = 0; t < count; ++t) {
    const float cx = u01(rng), cy = u01(rng), cz = u01(rng), size = 0.02f + 0.2f * u01(rng);
    for (int k = 0; k < 3; ++k) {
      const Vec3f p{cx + size * (u01(rng) - 0.5f), cy + size * (u01(rng) - 0.5f), cz + size * (u01(rng) - 0.5f)};
      s.positions.insert(s.positions.end(), {p[0], p[1], p[2]});
      s.normals.insert(s.normals.end(), {0.f, 1.f, 0.f});
      s.uvs.insert(s.uvs.end(), {3.f * u01(rng) - 1.f, 3.f * u01(rng) - 1.f});
      s.colors.insert(s.colors.end(), {1.f, 1.f, 1.f, u01(rng)});
      s.bounds.extend(p);
      s.indices.push_back(uint32_t(s.vertex_count() - 1));
    }
    s.tri_material.push_back(int32_t(t % 5) - 1);  // -1: the default material
  }
  return s;
}

TEST(GpuTraverse, RandomTrianglesWithAlphaMasks) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const Scene s = random_scene(7, 3000);
  expect_agreement(compare(*vk, s, 20000, 11), "random triangles");
}

// A quad whose texture alpha is 0 on its left half and 1 on its right: rays through the left
// half pass, through the right half stop, closest hit and shadow alike.
TEST(GpuTraverse, AlphaMaskCutsTheQuad) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  Scene s;
  Texture tex;
  tex.width = 2;
  tex.height = 1;
  tex.wrap_s = tex.wrap_t = 33071;
  tex.rgba8 = {255, 255, 255, 0, 255, 255, 255, 255};
  s.textures.push_back(tex);
  const int m = test::add_material(s, 0.5f);
  s.materials[size_t(m)].alpha_mode = AlphaMode::Mask;
  s.materials[size_t(m)].base_color_texture.texture = 0;
  test::add_quad(s, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, m);
  for (size_t v = 0; v < s.vertex_count(); ++v) s.uvs[v * 2] = s.positions[v * 3];  // u = x
  GpuSceneData data;
  ASSERT_TRUE(build_gpu_scene(s, {}, Context{}, data));
  EXPECT_EQ(data.alpha_triangles.size(), 2u);
  std::unique_ptr<GpuTracer> tracer;
  ASSERT_TRUE(GpuTracer::create(*vk, data, tracer));
  std::vector<gpu::GpuRay> rays;
  for (int i = 0; i < 10; ++i) rays.push_back({{0.05f + 0.1f * i, 0.5f, 1.f, 0.f}, {0.f, 0.f, -1.f, 5.f}});
  std::vector<gpu::GpuHit> hits;
  std::vector<uint32_t> blocked;
  ASSERT_TRUE(tracer->intersect(rays, hits));
  ASSERT_TRUE(tracer->occluded(rays, blocked));
  for (int i = 0; i < 10; ++i) {
    // Bilinear alpha across the two texel centres (x = 0.25, 0.75) reaches the 0.5 cutoff at 0.5.
    const bool solid = 0.05f + 0.1f * i > 0.5f;
    EXPECT_EQ(hits[size_t(i)].t_tri_uv.x > 0.f, solid) << i;
    EXPECT_EQ(blocked[size_t(i)] != 0, solid) << i;
    if (solid) {
      EXPECT_NEAR(hits[size_t(i)].t_tri_uv.x, 1.f, 1e-6f);
    }
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

TEST(GpuTraverse, SingleTriangleAndTinyScenes) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  Scene s;
  test::add_box(s, {0, 0, 0}, {1, 1, 1}, true, test::add_material(s, 0.5f));
  // A room: every ray from inside hits; every segment inside is unblocked.
  const Tally t = compare(*vk, s, 2000, 3);
  EXPECT_EQ(t.hits + t.ties, t.rays);
  EXPECT_EQ(t.bad_hit + t.bad_t + t.bad_prim + t.bad_shadow, 0u);
  EXPECT_EQ(t.blocked, 0u);
}

// Watertight on the device too: rays from inside a closed mesh aimed at its shared edges, and at
// its corners, all hit it and are all blocked (tests/bake/edge_rays.h). A triangle test that rounds
// each triangle on its own lets some through: light leaking into a closed room in a GPU bake.
TEST(GpuTraverse, RaysAtSharedEdgesAndCornersNeverEscapeAClosedMesh) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  Scene s;
  const Vec3f centre{3.7f, -1.3f, 0.6f};
  test::add_icosphere(s, centre, 10.f, 5, test::add_material(s, 0.5f));
  GpuSceneData data;
  ASSERT_TRUE(build_gpu_scene(s, {}, Context{}, data));
  std::unique_ptr<GpuTracer> tracer;
  ASSERT_TRUE(GpuTracer::create(*vk, data, tracer));
  std::vector<gpu::GpuRay> rays;
  for (const test::EdgeRay& r : test::rays_at_edges(s, centre, 8.f, 200000, 3, 8))
    rays.push_back({{r.org.x, r.org.y, r.org.z, 0.f}, {r.dir.x, r.dir.y, r.dir.z, INFINITY}});
  std::vector<gpu::GpuHit> hits;
  std::vector<uint32_t> blocked;
  ASSERT_TRUE(tracer->intersect(rays, hits));
  ASSERT_TRUE(tracer->occluded(rays, blocked));
  size_t missed = 0, unblocked = 0, corner_missed = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const bool miss = !(hits[i].t_tri_uv.x > 0.f);
    missed += miss;
    corner_missed += miss && i % 8 == 7;
    unblocked += blocked[i] == 0;
  }
  EXPECT_EQ(missed, 0u) << "of " << rays.size() << " closest-hit rays (" << corner_missed << " at corners)";
  EXPECT_EQ(unblocked, 0u) << "of " << rays.size() << " shadow rays";
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

Scene load(const char* rel) {
  Scene s;
  Context ctx;
  const Status st = import_scene(std::string(GIBAKE_ASSETS_DIR) + "/" + rel, {}, ctx, s);
  EXPECT_TRUE(st) << st.message();
  return s;
}

TEST(GpuTraverse, SponzaAgreesWithEmbree) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const Scene s = load("sponza/Sponza.gltf");
  ASSERT_GT(s.triangle_count(), 200000u);
  GpuSceneData data;
  ASSERT_TRUE(build_gpu_scene(s, {}, Context{}, data));
  std::printf("Sponza BVH: %zu nodes, %zu triangle refs, depth %u, %.1f bytes per triangle\n", data.nodes.size(),
              data.triangles.size(), data.depth, data.bvh_bytes_per_triangle());
  EXPECT_LT(data.depth, uint32_t(GPU_STACK));
  EXPECT_GT(data.alpha_triangles.size(), 0u);  // the plants and chains are masked
  expect_agreement(compare(*vk, s, 20000, 5), "Sponza");
}

TEST(GpuTraverse, SawAgreesWithEmbree) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  expect_agreement(compare(*vk, load("reciprocating-saw/ReciprocatingSaw.gltf"), 20000, 9), "ReciprocatingSaw");
}

TEST(GpuTraverse, DracoEngineAgreesWithEmbree) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  expect_agreement(compare(*vk, load("draco/2cylinderengine/2CylinderEngine.gltf"), 20000, 13), "2CylinderEngine");
}

TEST(GpuTraverse, AlphaBlendModeAsset) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  const Scene s = load("alpha-blend-mode-test/AlphaBlendModeTest.gltf");
  const Tally t = compare(*vk, s, 20000, 17);
  EXPECT_EQ(t.bad_hit + t.bad_t + t.bad_prim + t.bad_shadow, 0u);
  EXPECT_GT(t.hits, 0u);
}

}  // namespace
}  // namespace gibake
