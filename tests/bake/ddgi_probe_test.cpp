// Probe classification, relocation, determinism across thread counts, Embree face sign.
#include <gtest/gtest.h>

#include <embree3/rtcore.h>

#include <array>
#include <cstring>
#include <thread>

#include "bake/ddgi/classify.h"
#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/scene/prepare.h"
#include "io/inspect/mesh_diagnostics.h"
#include "tests/bake/scene_builders.h"

using namespace gibake;

namespace {
Status bake(const Scene& scene, const DdgiSettings& s, DdgiResult& r, DdgiReport& rep, unsigned threads = 0) {
  Context ctx;
  ctx.threads = threads;
  return bake_ddgi(scene, s, ctx, r, rep);
}
}  // namespace

// Embree 3 reports Ng along cross(v1-v0, v2-v0), the counter-clockwise (front) side, whatever the
// ray direction. A ray meeting the CCW side satisfies dot(dir, Ng_embree) < 0.
TEST(EmbreeFaces, GeometricNormalSign) {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene scene = rtcNewScene(device);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3));
  auto* ix = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, 1));
  const float verts[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};  // CCW seen from +z: Ng_ccw = +z
  std::memcpy(v, verts, sizeof verts);
  ix[0] = 0; ix[1] = 1; ix[2] = 2;
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  for (float dz : {-1.f, 1.f}) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray.org_x = 0.25f; rh.ray.org_y = 0.25f; rh.ray.org_z = -dz;
    rh.ray.dir_z = dz;
    rh.ray.tfar = 10.f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    ASSERT_NE(rh.hit.geomID, RTC_INVALID_GEOMETRY_ID);
    EXPECT_GT(rh.hit.Ng_z, 0.f) << "Embree Ng points to the counter-clockwise side";
    const bool front = is_front_face_embree({0, 0, dz}, {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z});
    EXPECT_EQ(front, dz < 0.f) << "coming from +z (dir -z) meets the CCW side";
  }
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);

  // The same through PreparedScene, using a Scene triangle.
  Scene s;
  test::add_triangle(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, test::add_material(s, 1.f));
  std::unique_ptr<PreparedScene> p;
  ASSERT_TRUE(PreparedScene::create(s, Context{}, p));
  const TraceHit from_front = p->intersect({0.25f, 0.25f, 1.f}, {0, 0, -1}, 0.f, 10.f);
  const TraceHit from_back = p->intersect({0.25f, 0.25f, -1.f}, {0, 0, 1}, 0.f, 10.f);
  EXPECT_TRUE(from_front.front);
  EXPECT_FALSE(from_back.front);
  EXPECT_NEAR(from_front.ng.z, 1.f, 1e-6f);
}

TEST(DdgiProbes, InsideClosedSolidIsInactive) {
  Scene scene;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/false, test::add_material(scene, 0.8f));
  DdgiSettings s;
  s.grid.explicit_bounds = true;
  s.grid.grid_min = {0, 0, 0};
  s.grid.grid_max = {4, 0, 0};
  s.grid.counts = {2, 1, 1};  // probe 0 inside the solid, probe 1 outside
  s.rays = 256;
  s.sky = {1, 1, 1};
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  EXPECT_EQ(r.states[0], ProbeState::Inactive);
  EXPECT_GT(r.stats[0].backface_fraction, 0.99f);
  EXPECT_EQ(r.states[1], ProbeState::Active);
  for (int c = 0; c < 27; ++c) EXPECT_EQ(r.sh[c], 0.f);
  EXPECT_GT(r.sh[27], 0.f);
  EXPECT_TRUE(rep.cgal_checked);
  EXPECT_EQ(rep.cgal_inside, 1u);
  EXPECT_EQ(rep.cgal_disagreements, 0u);
  EXPECT_EQ(rep.inactive, 1);
}

TEST(DdgiProbes, ProbeNearWallIsRelocatedAway) {
  Scene scene;
  test::add_quad(scene, {-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}, {0, 1, 0}, test::add_material(scene, 0.5f));
  DdgiSettings s;
  s.grid.explicit_bounds = true;
  s.grid.grid_min = {-1, 0.01f, -1};
  s.grid.grid_max = {1, 2.01f, 1};
  s.grid.counts = {3, 3, 3};  // 1 m cells; the bottom layer sits 1 cm above the floor
  s.rays = 128;
  s.sky = {1, 1, 1};
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake(scene, s, r, rep));
  for (int p = 0; p < 27; ++p) {
    const int y = (p / 3) % 3;
    const float* off = &r.offsets[p * 3];
    if (y == 0) {
      EXPECT_GT(off[1], 0.25f) << "probe " << p;  // threshold = 0.3 x 1 m
      EXPECT_LE(off[1], 0.45f + 1e-6f);
      EXPECT_LT(std::fabs(off[0]), 0.05f);
      EXPECT_LT(std::fabs(off[2]), 0.05f);
    } else {
      EXPECT_EQ(off[0], 0.f);
      EXPECT_EQ(off[1], 0.f);
      EXPECT_EQ(off[2], 0.f);
    }
    EXPECT_EQ(r.states[p], ProbeState::Active);
  }
  EXPECT_EQ(rep.relocated, 9);
}

TEST(DdgiProbes, SameBytesForAnyThreadCount) {
  Scene scene;
  test::add_box(scene, {-3, 0, -3}, {3, 3, 3}, /*inward=*/true, test::add_material(scene, 0.7f));
  test::add_box(scene, {-0.5f, 0, -0.5f}, {0.5f, 1.5f, 0.5f}, /*inward=*/false, test::add_material(scene, 0.4f));
  // An opening in the ceiling is simulated with a sun that reaches the floor through nothing:
  // use a point light instead, plus an emissive patch.
  Light light;
  light.type = Light::Type::Point;
  light.intensity = 50.f;
  light.position = {1.5f, 2.5f, 1.f};
  scene.lights.push_back(light);
  test::add_quad(scene, {-2, 2.99f, -2}, {-1, 2.99f, -2}, {-1, 2.99f, -1}, {-2, 2.99f, -1}, {0, -1, 0},
                 test::add_material(scene, 0.f, 20.f));
  DdgiSettings s;
  s.grid.counts = {4, 3, 4};
  s.grid.padding = 0.f;
  s.rays = 96;
  s.bounces = 2;
  s.target_error = 0.02f;
  s.max_rays = 384;
  s.seed = 99;
  DdgiResult a, b;
  DdgiReport ra, rb;
  ASSERT_TRUE(bake(scene, s, a, ra, 1));
  const unsigned many = std::max(2u, std::thread::hardware_concurrency());
  ASSERT_TRUE(bake(scene, s, b, rb, many));
  auto same = [](const auto& x, const auto& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  EXPECT_TRUE(same(a.sh, b.sh));
  EXPECT_TRUE(same(a.irradiance_atlas, b.irradiance_atlas));
  EXPECT_TRUE(same(a.depth_atlas, b.depth_atlas));
  EXPECT_TRUE(same(a.offsets, b.offsets));
  EXPECT_TRUE(same(a.states, b.states));
  EXPECT_TRUE(same(a.stats, b.stats));
  EXPECT_EQ(ra.total_rays(), rb.total_rays());
  // The adaptive budget did something: rays differ between probes.
  uint32_t lo = ~0u, hi = 0;
  for (const auto& st : a.stats) { lo = std::min(lo, st.rays); hi = std::max(hi, st.rays); }
  std::printf("determinism: %d probes, rays per probe %u..%u, %llu rays total, threads 1 vs %u\n", ra.probes, lo, hi,
              static_cast<unsigned long long>(ra.total_rays()), many);
  EXPECT_GT(ra.active, 0);
}

// classify_probes (ClosedMeshCheck) builds CGAL's solids on demand, only for the boxes that hold
// an asked probe; its report must equal the one of a tester with every solid built up front.
namespace {
ClassifyReport full_scene_report(const Scene& scene, const std::vector<float>& pos,
                                 const std::vector<DdgiProbeStats>& stats, float threshold) {
  ClassifyReport r;
  ClosedMeshInsideTester full(scene);
  if (!full.valid()) return r;
  bool any = false;
  for (const auto& st : stats) any = any || st.backface_fraction > 0.f;
  if (!any) return r;
  r.closed_mesh_checked = true;
  for (size_t i = 0; i < stats.size(); ++i) {
    if (stats[i].backface_fraction <= 0.f) continue;
    const int side = full.classify(&pos[i * 3]);
    if (side > 0) ++r.inside_by_cgal;
    if (side == 0) continue;
    const bool inactive = stats[i].backface_fraction > threshold;
    if (side > 0 && !inactive) ++r.disagreements;
    if (side < 0 && inactive) ++r.inactive_outside_closed;
  }
  return r;
}
}  // namespace

TEST(DdgiProbes, ClosedMeshReportMatchesWholeSceneTester) {
  Scene scene;
  const int m = test::add_material(scene, 0.8f);
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, false, m);     // solid A
  test::add_box(scene, {4, 4, 4}, {5, 5, 5}, false, m);        // solid B
  test::add_box(scene, {10, 10, 10}, {12, 12, 12}, true, m);   // inward: not a solid
  test::add_box(scene, {20, 20, 20}, {21, 21, 21}, false, m);  // closed box + a flap on an edge
  test::add_triangle(scene, {20, 21, 20}, {21, 21, 20}, {20.5f, 22, 19}, {0, 0, -1}, m);
  test::add_quad(scene, {-5, -3, -5}, {5, -3, -5}, {5, -3, 5}, {-5, -3, 5}, {0, 1, 0}, m);  // open plane
  test::add_box(scene, {40, 40, 40}, {41, 41, 41}, false, m);  // solid far from every probe
  const std::vector<std::array<float, 3>> points = {
      {0, 0, 0}, {4.5f, 4.5f, 4.5f}, {2, 2, 2}, {11, 11, 11}, {20.5f, 20.5f, 20.5f}, {0, 1, 0}, {30, 30, 30},
      {0.5f, 0.5f, 0.5f}, {0, -3, 0}};
  const float fractions[] = {0.9f, 0.1f, 0.5f, 0.9f, 0.9f, 0.5f, 0.f, 0.f, 0.3f};
  std::vector<float> pos;
  std::vector<DdgiProbeStats> stats(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    pos.insert(pos.end(), points[i].begin(), points[i].end());
    stats[i].backface_fraction = fractions[i];
  }
  auto check = [&](const std::vector<float>& p, const std::vector<DdgiProbeStats>& st) {
    std::vector<ProbeState> states;
    const ClassifyReport got = classify_probes(scene, p, st, 0.25f, true, states);
    const ClassifyReport want = full_scene_report(scene, p, st, 0.25f);
    EXPECT_EQ(got.closed_mesh_checked, want.closed_mesh_checked);
    EXPECT_EQ(got.inside_by_cgal, want.inside_by_cgal);
    EXPECT_EQ(got.disagreements, want.disagreements);
    EXPECT_EQ(got.inactive_outside_closed, want.inactive_outside_closed);
    for (size_t i = 0; i < st.size(); ++i)
      EXPECT_EQ(states[i], st[i].backface_fraction > 0.25f ? ProbeState::Inactive : ProbeState::Active);
    return want;
  };
  const ClassifyReport all = check(pos, stats);
  EXPECT_TRUE(all.closed_mesh_checked);
  EXPECT_EQ(all.inside_by_cgal, 2u);   // A and B
  EXPECT_EQ(all.disagreements, 1u);    // B's probe sees few back faces
  // Only probes far from every solid (near the plane and the non-solids): solids still exist.
  const std::vector<size_t> far_only = {3, 4, 8};
  std::vector<float> p2;
  std::vector<DdgiProbeStats> s2;
  for (size_t i : far_only) {
    p2.insert(p2.end(), points[i].begin(), points[i].end());
    s2.push_back(stats[i]);
  }
  const ClassifyReport far = check(p2, s2);
  EXPECT_TRUE(far.closed_mesh_checked);
  EXPECT_EQ(far.inactive_outside_closed, 3u);
}
