// LPV proofs: symmetric propagation, flux bounded and lost only through the border, a
// wall from a hand-built VoxelGrid cuts the light behind it, VPL flux in the documented units,
// determinism across thread counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <cstring>

#include "bake/lpv/lpv.h"
#include "bake/scene/lights.h"
#include "scene_builders.h"

namespace {

using namespace gibake;
using kernels::LpvCell;
using kernels::LpvGrid;
using kernels::LpvVpl;

LpvGrid make_grid(int x, int y, int z, float h = 1.f) {
  LpvGrid g;
  g.dims[0] = x, g.dims[1] = y, g.dims[2] = z;
  g.origin_cell[3] = h;
  return g;
}

// A VPL injected into cell c: placed half a cell behind the cell centre along its normal.
LpvVpl vpl_into(const LpvGrid& g, int cx, int cy, int cz, const kernels::float3& n, const kernels::float3& flux) {
  LpvVpl v;
  const float h = g.cell_size();
  const float c[3] = {(cx + 0.5f) * h, (cy + 0.5f) * h, (cz + 0.5f) * h};
  const float nn[3] = {n.x, n.y, n.z};
  for (int a = 0; a < 3; ++a) v.position[a] = g.origin_cell[a] + c[a] - 0.5f * h * nn[a];
  kernels::store3(v.normal, n);
  kernels::store3(v.flux, flux);
  return v;
}

std::vector<LpvCell> propagate(const LpvGrid& g, const std::vector<LpvVpl>& vpls, const float* geometry, int iterations,
                               std::vector<std::array<double, 3>>* flux = nullptr, unsigned threads = 0) {
  std::vector<LpvCell> cells(g.cells()), acc;
  EXPECT_EQ(kernels::lpv_inject(g, vpls.data(), vpls.size(), cells.data()), vpls.size());
  Context ctx;
  ctx.threads = threads;
  EXPECT_TRUE(lpv_propagate_volume(g, std::move(cells), geometry, iterations, ctx, acc, flux).is_ok());
  return acc;
}

float max_abs(const std::vector<LpvCell>& cells) {
  float m = 0.f;
  for (const LpvCell& c : cells)
    for (const auto& ch : c.sh)
      for (float v : ch) m = std::max(m, std::fabs(v));
  return m;
}

TEST(Lpv, CosineLobeProjectionMatchesQuadrature) {
  // Independent check of the cosine-lobe constants: integrate max(0, n.w) Y_i(w) numerically.
  const kernels::float3 n = kernels::normalize(kernels::float3{0.3f, -0.5f, 0.8f});
  double sums[4] = {0, 0, 0, 0};
  const int N = 400;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < 2 * N; ++j) {
      const double th = (i + 0.5) * M_PI / N, ph = (j + 0.5) * M_PI / N;
      const kernels::float3 w{float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th))};
      float y[4];
      kernels::lpv_sh_basis(w, y);
      const double f = std::max(0.0, double(kernels::dot(n, w))) * std::sin(th) * (M_PI / N) * (M_PI / N);
      for (int k = 0; k < 4; ++k) sums[k] += f * y[k];
    }
  float lobe[4];
  kernels::lpv_cosine_lobe(n, lobe);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(lobe[k], sums[k], 2e-4) << k;
}

TEST(Lpv, SolidAnglesTileTheSphere) {
  // The LPV solid-angle constants tile the sphere to 2e-5 (relative); the propagation renormalises each
  // cell's face fluxes to its flux, so this residue never creates or destroys light.
  EXPECT_NEAR(6.0 * (kernels::kLpvFacingSolidAngle + 4.0 * kernels::kLpvSideSolidAngle), 4.0 * M_PI, 3e-4);
}

// Mirror images of a cell value: reflecting axis a flips the sign of the band-1 coefficient
// along a (index 3 for x, 1 for y, 2 for z).
TEST(Lpv, SingleVplPropagatesSymmetrically) {
  const LpvGrid g = make_grid(17, 17, 17);
  const std::vector<LpvCell> acc =
      propagate(g, {vpl_into(g, 8, 8, 8, {0.f, 1.f, 0.f}, {10.f, 20.f, 30.f})}, nullptr, 12);
  const float tol = 2e-6f * max_abs(acc);  // float rounding of differently ordered sums
  int compared = 0;
  for (int z = 0; z < 17; ++z)
    for (int y = 0; y < 17; ++y)
      for (int x = 0; x < 17; ++x) {
        const LpvCell& a = acc[g.index(x, y, z)];
        const LpvCell& mx = acc[g.index(16 - x, y, z)];  // mirror in x
        const LpvCell& mz = acc[g.index(x, y, 16 - z)];  // mirror in z
        const LpvCell& sw = acc[g.index(z, y, x)];       // swap x and z
        for (int ch = 0; ch < 3; ++ch) {
          const float* v = a.sh[ch];
          EXPECT_NEAR(v[0], mx.sh[ch][0], tol);
          EXPECT_NEAR(v[1], mx.sh[ch][1], tol);
          EXPECT_NEAR(v[2], mx.sh[ch][2], tol);
          EXPECT_NEAR(v[3], -mx.sh[ch][3], tol);
          EXPECT_NEAR(v[2], -mz.sh[ch][2], tol);
          EXPECT_NEAR(v[3], mz.sh[ch][3], tol);
          EXPECT_NEAR(v[0], sw.sh[ch][0], tol);
          EXPECT_NEAR(v[1], sw.sh[ch][1], tol);
          EXPECT_NEAR(v[2], sw.sh[ch][3], tol);
          EXPECT_NEAR(v[3], sw.sh[ch][2], tol);
          ++compared;
        }
      }
  EXPECT_EQ(compared, 17 * 17 * 17 * 3);
  // Light went upwards (the lobe's side) more than downwards.
  EXPECT_GT(acc[g.index(8, 12, 8)].sh[0][0], acc[g.index(8, 4, 8)].sh[0][0]);
  EXPECT_GT(acc[g.index(8, 4, 8)].sh[0][0], 0.f);
}

TEST(Lpv, IsotropicSourceHasCubicSymmetry) {
  const LpvGrid g = make_grid(15, 15, 15);
  std::vector<LpvVpl> vpls;
  const kernels::float3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const auto& n : axes) vpls.push_back(vpl_into(g, 7, 7, 7, n, {1.f, 1.f, 1.f}));
  const std::vector<LpvCell> acc = propagate(g, vpls, nullptr, 10);
  const float tol = 2e-6f * max_abs(acc);
  for (int z = 0; z < 15; ++z)
    for (int y = 0; y < 15; ++y)
      for (int x = 0; x < 15; ++x) {
        const float c0 = acc[g.index(x, y, z)].sh[0][0];
        EXPECT_NEAR(c0, acc[g.index(y, z, x)].sh[0][0], tol);
        EXPECT_NEAR(c0, acc[g.index(14 - x, y, z)].sh[0][0], tol);
        EXPECT_NEAR(c0, acc[g.index(x, 14 - y, z)].sh[0][0], tol);
        EXPECT_NEAR(c0, acc[g.index(z, x, 14 - y)].sh[0][0], tol);
      }
}

// Total flux = sqrt(4 pi) * sum of c0 over the cells of the propagating front (not the
// accumulated volume), per channel, summed in double.
TEST(Lpv, FluxNeverExceedsInjectedAndLeavesOnlyThroughTheBorder) {
  const LpvGrid g = make_grid(21, 21, 21);
  const kernels::float3 flux{1.f, 2.f, 3.f};
  const kernels::float3 n = kernels::normalize(kernels::float3{0.3f, 0.9f, -0.2f});
  std::vector<std::array<double, 3>> steps;
  propagate(g, {vpl_into(g, 10, 10, 10, n, flux)}, nullptr, 60, &steps);
  ASSERT_EQ(steps.size(), 60u);
  const double injected[3] = {1.0, 2.0, 3.0};
  double previous[3] = {1.0, 2.0, 3.0};
  for (size_t k = 0; k < steps.size(); ++k)
    for (int c = 0; c < 3; ++c) {
      const double f = steps[k][c];
      EXPECT_LE(f, injected[c] * (1.0 + 1e-5)) << "step " << k + 1;
      EXPECT_LE(f, previous[c] * (1.0 + 1e-6)) << "step " << k + 1;  // never grows
      // The front reaches the border cells (index 0, 20) after 10 steps; until then no flux may leave.
      if (k + 1 <= 10) {
        EXPECT_NEAR(f, injected[c], 1e-5 * injected[c]) << "step " << k + 1;
      }
      previous[c] = f;
    }
  EXPECT_LT(steps[11][0], 1.0 - 1e-7);  // leaves once the front has crossed the border
  EXPECT_LT(steps[59][0], 0.9);         // propagation is diffusive: after 60 steps ~81% is left
}

// The gather is diffusive: after N steps a source's light reaches about sqrt(N) cells. The default
// step count (a quarter of the longest axis squared) carries a source at the grid's centre to the
// border at about inverse-square irradiance; 16 steps light only the first few cells.
TEST(Lpv, PropagationIsDiffusiveAndTheDefaultReachesHalfTheGrid) {
  const LpvGrid g = make_grid(24, 24, 24);
  const int n = lpv_default_iterations(g);
  EXPECT_EQ(n, 144);
  EXPECT_EQ(lpv_default_iterations(make_grid(256, 40, 7)), 4096);  // capped
  EXPECT_EQ(lpv_default_iterations(make_grid(1, 1, 1)), 1);
  const kernels::float3 flux{1.f, 1.f, 1.f};
  const std::vector<LpvVpl> vpls = {vpl_into(g, 12, 4, 12, {0.f, 1.f, 0.f}, flux)};
  const std::vector<LpvCell> few = propagate(g, vpls, nullptr, 16);
  const std::vector<LpvCell> full = propagate(g, vpls, nullptr, n);
  // Irradiance on a surface facing the source r cells above it, over the inverse-square value
  // Phi / (pi r^2) of the VPL's cosine lobe (h = 1).
  const auto ratio = [&](const std::vector<LpvCell>& acc, int r) {
    const float e = kernels::lpv_cell_irradiance(acc[g.index(12, 4 + r, 12)], {0.f, -1.f, 0.f}, 1.f).x;
    return e * float(M_PI) * float(r * r) / flux.x;
  };
  for (int r = 1; r <= 12; ++r) {
    EXPECT_GT(ratio(full, r), 0.5f) << r;
    EXPECT_LT(ratio(full, r), 1.5f) << r;
  }
  EXPECT_GT(ratio(few, 2), 0.7f * ratio(full, 2));  // within sqrt(16) cells: mostly there
  EXPECT_LT(ratio(few, 8), 0.1f * ratio(full, 8));  // twice that: not yet
}

// A solid wall two voxels thick (front faces towards the light, back faces away) between a VPL
// and the far part of the grid.
VoxelGrid wall_grid(bool both_faces) {
  VoxelGrid v;
  v.voxel_size = 0.5f;
  v.dims = {40, 18, 18};
  v.space.assign(size_t(40) * 18 * 18, uint8_t(VoxelSpace::Exterior));
  for (int k = 0; k < 18; ++k)
    for (int j = 0; j < 18; ++j)
      for (int i : {20, 21}) {
        if (i == 21 && !both_faces) continue;
        SurfaceVoxel s;
        s.ijk[0] = i, s.ijk[1] = j, s.ijk[2] = k;
        s.fragments = 2;
        s.coverage = 1.f;
        s.normal[0] = i == 20 ? -1.f : 1.f;
        s.albedo[0] = s.albedo[1] = s.albedo[2] = 0.5f;
        v.space[size_t(v.linear(i, j, k))] = uint8_t(VoxelSpace::Surface);
        v.surface.push_back(s);
      }
  std::sort(v.surface.begin(), v.surface.end(), [&](const SurfaceVoxel& a, const SurfaceVoxel& b) {
    return v.linear(a.ijk[0], a.ijk[1], a.ijk[2]) < v.linear(b.ijk[0], b.ijk[1], b.ijk[2]);
  });
  return v;
}

double flux_behind(const LpvGrid& g, const std::vector<LpvCell>& acc, int from_x) {
  double f = 0.0;
  for (int z = 0; z < g.dims[2]; ++z)
    for (int y = 0; y < g.dims[1]; ++y)
      for (int x = from_x; x < g.dims[0]; ++x) f += kernels::lpv_cell_flux(acc[g.index(x, y, z)], 0);
  return f;
}

TEST(Lpv, WallFromVoxelGridCutsLightBehindIt) {
  const LpvGrid g = make_grid(20, 9, 9);
  const std::vector<LpvVpl> vpls = {vpl_into(g, 3, 4, 4, {1.f, 0.f, 0.f}, {100.f, 100.f, 100.f})};
  const std::vector<LpvCell> open = propagate(g, vpls, nullptr, 20);
  for (bool both : {true, false}) {
    std::vector<float> geometry;
    lpv_geometry_volume(wall_grid(both), g, geometry);
    ASSERT_EQ(geometry.size(), size_t(21 * 10 * 10 * 4));
    std::vector<std::array<double, 3>> steps;
    const std::vector<LpvCell> walled = propagate(g, vpls, geometry.data(), 20, &steps);
    double previous = 100.0;  // injected (lm); occlusion only ever removes light
    for (const auto& f : steps) {
      EXPECT_LE(f[0], previous * (1.0 + 1e-6));
      previous = f[0];
    }
    const double before = flux_behind(g, open, 11), after = flux_behind(g, walled, 11);
    ASSERT_GT(before, 1.0);
    EXPECT_LE(after, 0.1 * before) << "both faces " << both << ": " << after << " of " << before;
    // In front of the wall the light is still there (within a factor: the wall keeps it from escaping).
    EXPECT_GT(flux_behind(g, walled, 0) - after, 0.5 * (flux_behind(g, open, 0) - before));
  }
}

TEST(Lpv, DeterministicForAnyThreadCount) {
  const LpvGrid g = make_grid(12, 10, 14);
  std::vector<LpvVpl> vpls;
  for (int i = 0; i < 20; ++i)
    vpls.push_back(vpl_into(g, i % 12, (i * 7) % 10, (i * 5) % 14,
                            kernels::normalize(kernels::float3{float(i % 3) - 1.f, 1.f, float(i % 5) - 2.f}),
                            {float(i), 1.f, 2.f}));
  std::vector<float> geometry;
  lpv_geometry_volume(wall_grid(true), g, geometry);
  const std::vector<LpvCell> a = propagate(g, vpls, geometry.data(), 9, nullptr, 1);
  const std::vector<LpvCell> b = propagate(g, vpls, geometry.data(), 9, nullptr, 2);
  const std::vector<LpvCell> c = propagate(g, vpls, geometry.data(), 9, nullptr, 0);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(LpvCell)), 0);
  EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(LpvCell)), 0);
}

// VPL units: a sun of E lux on a floor of albedo rho and area A reflects rho * E * A lumens; a
// single-sided emissive quad of radiance L and area A emits pi * L * A.
TEST(LpvVpls, SunOnFloorAndEmitterCarryTheirFlux) {
  Scene scene;
  const int floor = test::add_material(scene, 0.5f);
  test::add_quad(scene, {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}, {0, 1, 0}, floor);
  const int emitter = test::add_material(scene, 0.f, 3.f);
  test::add_quad(scene, {-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}, {0, -1, 0}, emitter);
  Context ctx;
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(scene, ctx, prepared).is_ok());
  SunLight sun;
  sun.direction = {0.f, -1.f, 0.f};
  sun.lux = 1000.f;
  LpvSettings s;
  s.vpl_samples = 40000;
  s.emissive_samples = 5000;
  std::vector<LpvVpl> vpls;
  LpvStats stats;
  ASSERT_TRUE(generate_vpls(scene, *prepared, shade_lights(scene, {sun}), s, ctx, vpls, stats).is_ok());
  double sun_flux = 0.0, emitted = 0.0;
  for (const LpvVpl& v : vpls) (v.normal[1] > 0.f ? sun_flux : emitted) += v.flux[0];
  // The emitter (albedo 0, its top is its back face) shadows 1 of the floor's 16 m^2.
  EXPECT_NEAR(sun_flux, 0.5 * 1000.0 * 15.0, 0.01 * 0.5 * 1000.0 * 15.0);
  EXPECT_NEAR(emitted, M_PI * 3.0 * 1.0, 1e-4 * M_PI * 3.0);
  EXPECT_EQ(stats.emissive_vpls, 5000u);
}

TEST(LpvVpls, PointLightInClosedRoomReflectsAlbedoTimesFourPiI) {
  Scene scene;
  const int wall = test::add_material(scene, 0.25f);
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, true, wall);
  Light l;
  l.type = Light::Type::Point;
  l.intensity = 50.f;
  l.position = {0.1f, 0.2f, -0.3f};
  scene.lights.push_back(l);
  Context ctx;
  std::unique_ptr<PreparedScene> prepared;
  ASSERT_TRUE(PreparedScene::create(scene, ctx, prepared).is_ok());
  LpvSettings s;
  s.vpl_samples = 20000;
  std::vector<LpvVpl> vpls;
  LpvStats stats;
  ASSERT_TRUE(generate_vpls(scene, *prepared, shade_lights(scene, {}), s, ctx, vpls, stats).is_ok());
  double total = 0.0;
  for (const LpvVpl& v : vpls) total += v.flux[1];
  EXPECT_NEAR(total, 0.25 * 4.0 * M_PI * 50.0, 1e-3 * 0.25 * 4.0 * M_PI * 50.0);
  EXPECT_EQ(vpls.size(), 20000u);
}

TEST(LpvBake, CascadesNestAndBakeIsDeterministic) {
  Scene scene;
  const int wall = test::add_material(scene, 0.6f);
  test::add_box(scene, {-2, 0, -1}, {2, 2, 1}, true, wall);
  Light l;
  l.type = Light::Type::Point;
  l.intensity = 10.f;
  l.position = {0.f, 1.5f, 0.f};
  scene.lights.push_back(l);
  std::unique_ptr<PreparedScene> prepared;
  Context ctx;
  ASSERT_TRUE(PreparedScene::create(scene, ctx, prepared).is_ok());
  LpvSettings s;
  s.resolution = 12;
  s.cascades = 2;
  s.vpl_samples = 4096;
  LpvResult a, b;
  ctx.threads = 1;
  ASSERT_TRUE(bake_lpv(scene, *prepared, shade_lights(scene, {}), nullptr, s, ctx, a).is_ok());
  ctx.threads = 2;
  ASSERT_TRUE(bake_lpv(scene, *prepared, shade_lights(scene, {}), nullptr, s, ctx, b).is_ok());
  ASSERT_EQ(a.cascades.size(), 2u);
  EXPECT_EQ(a.cascades[0].sh, b.cascades[0].sh);
  EXPECT_EQ(a.cascades[1].sh, b.cascades[1].sh);
  EXPECT_FLOAT_EQ(a.cascades[1].cell_size, 2.f * a.cascades[0].cell_size);
  EXPECT_EQ(a.cascades[1].dims, (std::array<int32_t, 3>{12, 7, 7}));
  EXPECT_EQ(a.cascades[1].iterations, 36u);  // a quarter of the longest axis squared
  for (int ax = 0; ax < 3; ++ax)  // same centre
    EXPECT_NEAR(a.cascades[0].grid_min[ax] + 0.5f * a.cascades[0].dims[ax] * a.cascades[0].cell_size,
                a.cascades[1].grid_min[ax] + 0.5f * a.cascades[1].dims[ax] * a.cascades[1].cell_size, 1e-5f);
  const std::vector<DenseGridExport> grids = lpv_dense_grids(a);
  ASSERT_EQ(grids.size(), 12u);
  EXPECT_EQ(grids[0].name, "lpv0_r_sh0");
  EXPECT_EQ(grids[1].name, "lpv0_r_sh1");
  EXPECT_EQ(grids[1].values.size(), a.cascades[0].cell_count() * 3);
}

// A closed double-sided emissive cube: the VPLs of its inner faces leave into Interior voxels and
// are dropped when a voxel grid is given; the geometry volume then blocks the rest at the walls.
TEST(LpvBake, VoxelGridDropsInteriorVplsAndOccludes) {
  Scene scene;
  const int emitter = test::add_material(scene, 0.f, 2.f, true);
  test::add_box(scene, {-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, false, emitter);
  const int floor = test::add_material(scene, 0.5f);
  test::add_quad(scene, {-3, -1, -3}, {3, -1, -3}, {3, -1, 3}, {-3, -1, 3}, {0, 1, 0}, floor);
  std::unique_ptr<PreparedScene> prepared;
  Context ctx;
  ASSERT_TRUE(PreparedScene::create(scene, ctx, prepared).is_ok());
  // Voxels of 0.1 m over [-3, 3]^3: the cube's shell (one voxel) is Surface, its inside Interior.
  VoxelGrid v;
  v.voxel_size = 0.1f;
  v.origin = {-3.f, -3.f, -3.f};
  v.dims = {60, 60, 60};
  v.space.assign(size_t(60) * 60 * 60, uint8_t(VoxelSpace::Exterior));
  for (int k = 25; k < 35; ++k)
    for (int j = 25; j < 35; ++j)
      for (int i = 25; i < 35; ++i) {
        const bool shell = i == 25 || i == 34 || j == 25 || j == 34 || k == 25 || k == 34;
        v.space[size_t(v.linear(i, j, k))] = uint8_t(shell ? VoxelSpace::Surface : VoxelSpace::Interior);
      }
  LpvSettings s;
  s.resolution = 16;
  s.emissive_samples = 6000;
  LpvResult with, without;
  ASSERT_TRUE(bake_lpv(scene, *prepared, {}, nullptr, s, ctx, without).is_ok());
  ASSERT_TRUE(bake_lpv(scene, *prepared, {}, &v, s, ctx, with).is_ok());
  EXPECT_EQ(without.stats.interior_vpls, 0u);
  EXPECT_EQ(with.stats.emissive_vpls, 12000u);  // both sides of every sample
  // The inner sides, except within about a voxel of the cube's edges where the points in front
  // land in the shell of the neighbouring face: (8/10)^2 of each face.
  EXPECT_GE(with.stats.interior_vpls, 3500u);
  EXPECT_LE(with.stats.interior_vpls, 6000u);
  double flux_with = 0.0, flux_without = 0.0;
  for (size_t i = 0; i < with.cascades[0].cell_count(); ++i) {
    flux_with += with.cascades[0].sh[i * 12];
    flux_without += without.cascades[0].sh[i * 12];
  }
  EXPECT_LT(flux_with, 0.75 * flux_without);
}

}  // namespace
