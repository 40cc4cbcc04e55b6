// Voxel channels (albedo from textures, emission, normal, anisotropic faces, coverage, direct
// irradiance with shadow rays), the signed distance field, and the VDB file read back with
// OpenVDB. Answers: analytic (E cos(theta), the sRGB formula, plane geometry, sphere distance).
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <unistd.h>

#include "bake/scene/lights.h"
#include "bake/voxel/voxelize.h"
#include "io/export/voxels_vdb.h"
#include "tests/bake/scene_builders.h"
#include "tests/bake/voxel_test_util.h"
#include "tests/support/scratch_dir.h"

namespace gibake {
namespace {

// Whether the voxel lies at least `margin` metres inside the rectangle [x0,x1] x [z0,z1].
bool well_inside(const VoxelGrid& g, const SurfaceVoxel& s, float x0, float x1, float z0, float z1, float margin) {
  const auto c = g.voxel_center(s.ijk[0], s.ijk[1], s.ijk[2]);
  return c[0] > x0 + margin && c[0] < x1 - margin && c[2] > z0 + margin && c[2] < z1 - margin;
}

std::vector<kernels::ShadeLight> sun(float dx, float dy, float dz, float lux) {
  SunLight s;
  s.direction = {dx, dy, dz};
  s.lux = lux;
  return shade_lights(Scene{}, {s});
}

// A 4 m floor lit by a sun at 35 degrees from the zenith, a box casting a shadow on it.
TEST(VoxelChannels, SunlitPlaneDirectIsECosTheta) {
  Scene s;
  const int m = test::add_material(s, 0.6f);
  test::add_quad(s, {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}, {0, 1, 0}, m);
  test::add_box(s, {1.0f, 1.0f, 1.0f}, {1.6f, 1.2f, 1.6f}, false, m);
  const float th = 35.f * 3.14159265f / 180.f, E = 1000.f;
  VoxelSettings vs;
  vs.resolution = 48;
  vs.sdf = false;
  VoxelGrid g;
  VoxelReport rep;
  ASSERT_TRUE(voxelize(s, vs, sun(-std::sin(th), -std::cos(th), 0.f, E), nullptr, Context{}, g, &rep).is_ok());
  EXPECT_GT(rep.shadow_rays, 0u);
  size_t lit = 0, dark = 0;
  for (const SurfaceVoxel& v : g.surface) {
    const auto c = g.voxel_center(v.ijk[0], v.ijk[1], v.ijk[2]);
    if (c[1] > 0.5f || !well_inside(g, v, -2, 2, -2, 2, g.voxel_size)) continue;
    // The sun travels -x: the box (x in [1, 1.6], y in [1, 1.2]) shadows x in [1 - 1.2 tan(theta),
    // 1.6 - tan(theta)] = [0.16, 0.90], z in [1, 1.6].
    const bool shadowed = c[0] > 0.3f && c[0] < 0.8f && c[2] > 1.1f && c[2] < 1.5f;
    const bool clear = c[2] < 0.8f || c[2] > 1.8f || c[0] < -0.1f || c[0] > 1.0f;
    if (clear) {
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(v.direct[k], E * std::cos(th), 0.01f * E * std::cos(th));
      ++lit;
    } else if (shadowed) {
      EXPECT_EQ(v.direct[0], 0.f);
      ++dark;
    }
  }
  EXPECT_GT(lit, 500u);
  EXPECT_GT(dark, 5u);
}

TEST(VoxelChannels, SingleSidedBackFaceGetsNoDirectLight) {
  Scene s;
  const int m = test::add_material(s, 0.6f);
  test::add_quad(s, {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}, {0, -1, 0}, m);  // faces down
  VoxelSettings vs;
  vs.resolution = 16;
  vs.sdf = false;
  VoxelGrid g;
  ASSERT_TRUE(voxelize(s, vs, sun(0, -1, 0, 500.f), nullptr, Context{}, g).is_ok());
  for (const SurfaceVoxel& v : g.surface) EXPECT_EQ(v.direct[1], 0.f);
  s.materials[0].double_sided = true;  // lit from above as well
  ASSERT_TRUE(voxelize(s, vs, sun(0, -1, 0, 500.f), nullptr, Context{}, g).is_ok());
  for (const SurfaceVoxel& v : g.surface)
    if (well_inside(g, v, -2, 2, -2, 2, g.voxel_size)) {
      EXPECT_NEAR(v.direct[1], 500.f, 1.f);
    }
}

float srgb_to_linear(uint8_t c) {
  const float x = c / 255.f;
  return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
}

// A floor textured with a 2x2 checker of 4x4-texel blocks (so bilinear filtering is exact inside
// a block), base colour factor 0.5, emission 3 cd/m^2.
TEST(VoxelChannels, AlbedoFromTexturesEmissionNormalAnisoCoverage) {
  Scene s;
  Texture tex;
  tex.width = tex.height = 8;
  const uint8_t colours[2][3] = {{200, 40, 90}, {30, 180, 250}};
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const uint8_t* c = colours[((x / 4) + (y / 4)) % 2];
      tex.rgba8.insert(tex.rgba8.end(), {c[0], c[1], c[2], 255});
    }
  s.textures.push_back(tex);
  const int m = test::add_material(s, 0.5f, 3.f);
  s.materials[m].base_color_texture.texture = 0;
  test::add_quad(s, {0, 0, 0}, {4, 0, 0}, {4, 0, 4}, {0, 0, 4}, {0, 1, 0}, m);
  for (size_t i = 0; i < s.vertex_count(); ++i) {  // uv = (x, z) / 4
    s.uvs[i * 2] = s.positions[i * 3] / 4.f;
    s.uvs[i * 2 + 1] = s.positions[i * 3 + 2] / 4.f;
  }
  VoxelSettings vs;
  vs.resolution = 32;
  vs.sdf = false;
  VoxelGrid g;
  ASSERT_TRUE(voxelize(s, vs, Context{}, g).is_ok());
  size_t checked = 0;
  for (const SurfaceVoxel& v : g.surface) {
    const auto c = g.voxel_center(v.ijk[0], v.ijk[1], v.ijk[2]);
    EXPECT_NEAR(v.normal[1], 1.f, 1e-6f);
    EXPECT_NEAR(v.aniso[2], 1.f, 1e-6f);  // +y
    EXPECT_EQ(v.aniso[3], 0.f);
    EXPECT_NEAR(v.emission[0], 3.f, 1e-5f);
    // Block (bx, bz) of 2 m; texel rows run along v = z / 4 (glTF v down the image is irrelevant
    // here: the checker is symmetric in its block parity).
    const float fx = c[0] / 2.f, fz = c[2] / 2.f;
    if (std::fabs(fx - std::round(fx)) < 0.35f || std::fabs(fz - std::round(fz)) < 0.35f) continue;
    if (c[0] < 0.6f || c[0] > 3.4f || c[2] < 0.6f || c[2] > 3.4f) continue;
    const uint8_t* want = colours[(int(fx) + int(fz)) % 2];
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(v.albedo[k], 0.5f * srgb_to_linear(want[k]), 1e-4f) << k;
    EXPECT_NEAR(v.coverage, 1.f, 1e-5f);  // the floor crosses the whole voxel
    ++checked;
  }
  EXPECT_GE(checked, 64u);
}

// A tilted plane: normal and aniso faces from its normal; the coverage (fragments' area projected
// onto their dominant axis) of a column of voxels along that axis sums to the face area, 1.
TEST(VoxelChannels, TiltedPlaneNormalAnisoAndCoverageColumns) {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  // Plane y = 0.3 x - 0.45 z + 1, normal ~ (-0.3, 1, 0.45).
  auto p = [](float x, float z) { return Vec3f{x, 0.3f * x - 0.45f * z + 1.f, z}; };
  const float l = std::sqrt(0.09f + 1.f + 0.2025f);
  const float n[3] = {-0.3f / l, 1.f / l, 0.45f / l};
  test::add_quad(s, p(0, 0), p(4, 0), p(4, 4), p(0, 4), {n[0], n[1], n[2]}, m);
  VoxelSettings vs;
  vs.resolution = 24;
  vs.sdf = false;
  VoxelGrid g;
  ASSERT_TRUE(voxelize(s, vs, Context{}, g).is_ok());
  std::vector<double> column(size_t(g.dims[0]) * g.dims[2], 0.0);
  for (const SurfaceVoxel& v : g.surface) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(v.normal[k], n[k], 1e-5f);
    const float want[6] = {std::max(0.f, n[0]), std::max(0.f, -n[0]), std::max(0.f, n[1]),
                           std::max(0.f, -n[1]), std::max(0.f, n[2]), std::max(0.f, -n[2])};
    for (int f = 0; f < 6; ++f) EXPECT_NEAR(v.aniso[f], want[f], 1e-5f);
    column[size_t(v.ijk[0]) + size_t(g.dims[0]) * v.ijk[2]] += v.coverage;
  }
  size_t full = 0;
  for (int32_t z = 0; z < g.dims[2]; ++z)
    for (int32_t x = 0; x < g.dims[0]; ++x) {
      const auto c = g.voxel_center(x, 0, z);
      if (c[0] < g.voxel_size || c[0] > 4 - g.voxel_size || c[2] < g.voxel_size || c[2] > 4 - g.voxel_size) continue;
      EXPECT_NEAR(column[size_t(x) + size_t(g.dims[0]) * z], 1.0, 1e-4) << x << "," << z;
      ++full;
    }
  EXPECT_GT(full, 300u);
}

TEST(VoxelChannels, MaskedOutFragmentsOccupyButDoNotCover) {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  s.materials[m].alpha_mode = AlphaMode::Mask;
  s.materials[m].base_color[3] = 0.2f;  // below the 0.5 cutoff everywhere
  test::add_quad(s, {0, 0, 0}, {4, 0, 0}, {4, 0, 4}, {0, 0, 4}, {0, 1, 0}, m);
  VoxelSettings vs;
  vs.resolution = 16;
  vs.sdf = false;
  VoxelGrid g;
  ASSERT_TRUE(voxelize(s, vs, Context{}, g).is_ok());
  ASSERT_FALSE(g.surface.empty());
  for (const SurfaceVoxel& v : g.surface) EXPECT_EQ(v.coverage, 0.f);
}

TEST(VoxelChannels, LitVoxelsAreTheSameForAnyThreadCount) {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  test::add_box(s, {-3, 0, -3}, {3, 3, 3}, true, m);
  test::add_sphere(s, {0.2f, 1.2f, 0.1f}, 0.9f, 64, 32, m);
  Light point;
  point.type = Light::Type::Point;
  point.intensity = 300.f;
  point.position = {1.5f, 2.5f, -1.f};
  s.lights.push_back(point);
  const auto lights = shade_lights(s, {});
  VoxelSettings vs;
  vs.resolution = 40;
  VoxelGrid a, b;
  Context c1, c4;
  c1.threads = 1;
  c4.threads = 4;
  ASSERT_TRUE(voxelize(s, vs, lights, nullptr, c1, a).is_ok());
  ASSERT_TRUE(voxelize(s, vs, lights, nullptr, c4, b).is_ok());
  ASSERT_EQ(a.surface.size(), b.surface.size());
  EXPECT_EQ(0, std::memcmp(a.surface.data(), b.surface.data(), a.surface.size() * sizeof(SurfaceVoxel)));
  EXPECT_EQ(a.sdf, b.sdf);
  // The point light reaches the room's walls: some voxels are lit, the sphere shadows others.
  size_t lit = 0;
  for (const SurfaceVoxel& v : a.surface) lit += v.direct[0] > 0.f;
  EXPECT_GT(lit, a.surface.size() / 4);
  EXPECT_LT(lit, a.surface.size());
}

// A closed sphere: SDF negative inside; next to the surface (|d| < 0.8 voxel) OpenVDB's exact
// distance (up to the tessellation); further out a lower bound of the true distance within
// sqrt(3) voxels of it.
TEST(VoxelSdf, SphereDistanceAndSign) {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  const float r = 1.f;
  test::add_sphere(s, {0, 0, 0}, r, 96, 48, m);
  test::add_triangle(s, {-3, -3, -3}, {-3, -3, -3}, {-3, -3, -3}, {0, 1, 0}, m);  // widen the grid
  VoxelSettings vs;
  vs.resolution = 64;
  VoxelGrid g;
  ASSERT_TRUE(voxelize(s, vs, Context{}, g).is_ok());
  ASSERT_EQ(g.sdf.size(), g.space.size());
  // Tessellation: the mesh lies inside the sphere by at most r (1 - cos(pi/48)) (rings of pi/48).
  const float h = g.voxel_size, tess = r * (1.f - std::cos(3.14159265f / 48.f)) + 1e-4f;
  size_t near = 0, far = 0;
  for (int32_t z = 0; z < g.dims[2]; ++z)
    for (int32_t y = 0; y < g.dims[1]; ++y)
      for (int32_t x = 0; x < g.dims[0]; ++x) {
        const auto c = g.voxel_center(x, y, z);
        // Nearest surface: the sphere or the point triangle at (-3,-3,-3).
        const float ds = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) - r;
        const float dp = std::sqrt((c[0] + 3) * (c[0] + 3) + (c[1] + 3) * (c[1] + 3) + (c[2] + 3) * (c[2] + 3));
        const float d = std::fabs(ds) < dp ? ds : dp;
        const float v = g.sdf[size_t(g.linear(x, y, z))];
        const auto sp = static_cast<VoxelSpace>(g.space[size_t(g.linear(x, y, z))]);
        if (sp == VoxelSpace::Interior) {
          ASSERT_LT(v, 0.f);
        } else if (sp == VoxelSpace::Exterior) {
          ASSERT_GT(v, 0.f);
        }
        if (std::fabs(d) > 0.25f * h) {  // surface voxels' sign comes from the nearest empty space
          ASSERT_EQ(v < 0.f, d < 0.f) << x << "," << y << "," << z;
        }
        if (std::fabs(d) < 0.8f * h) {
          ASSERT_NEAR(std::fabs(v), std::fabs(d), tess) << x << "," << y << "," << z;
          ++near;
        } else {
          ASSERT_LE(std::fabs(v), std::fabs(d) + tess) << x << "," << y << "," << z;
          ASSERT_GE(std::fabs(v), std::fabs(d) - 1.7321f * h - tess) << x << "," << y << "," << z;
          ++far;
        }
      }
  EXPECT_GT(near, 1000u);
  EXPECT_GT(far, 10000u);
}

std::string scratch(const std::string& name) {
  const auto dir = gibake::test::process_tmp() / "voxel_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(VoxelVdb, WritesNamedGridsThatOpenVdbReadsBack) {
  Scene s;
  const int m = test::add_material(s, 0.7f, 2.f);
  test::add_box(s, {0, 0, 0}, {1, 1, 1}, false, m);
  VoxelSettings vs;
  vs.resolution = 12;
  VoxelGrid g;
  ASSERT_TRUE(voxelize(s, vs, sun(0, -1, 0, 100.f), nullptr, Context{}, g).is_ok());
  DenseGridExport sh;
  sh.name = "lpv_r";
  sh.origin = {-1.f, -1.f, -1.f};
  sh.voxel_size = 0.5f;
  sh.dims = {4, 4, 4};
  sh.channels = 3;
  sh.values.assign(4 * 4 * 4 * 3, 0.f);
  sh.values[(1 + 4 * (2 + 4 * 3)) * 3 + 1] = 7.f;
  const std::string path = scratch("box.vdb");
  VoxelVdbOptions opt;
  opt.settings_json = voxel_settings_json(vs);
  ASSERT_TRUE(write_voxels_vdb(path, g, {sh}, opt).is_ok());

  openvdb::initialize();
  openvdb::io::File f(path);
  f.open();
  auto meta = f.getMetadata();
  EXPECT_EQ(meta->metaValue<float>("gibake:voxel_size"), g.voxel_size);
  EXPECT_EQ(meta->metaValue<std::string>("gibake:settings"), opt.settings_json);
  openvdb::GridPtrVecPtr grids = f.getGrids();
  f.close();
  std::vector<std::string> names;
  for (const auto& grid : *grids) names.push_back(grid->getName());
  for (const std::string& want : voxel_vdb_grid_names())
    EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
  auto find = [&](const std::string& n) { return openvdb::findGridByName(*grids, n); };
  // Transform: index (i,j,k) is at voxel (i,j,k)'s centre.
  const SurfaceVoxel& sv = g.surface[g.surface.size() / 2];
  const openvdb::Vec3d w = find("albedo")->transform().indexToWorld(openvdb::Coord(sv.ijk[0], sv.ijk[1], sv.ijk[2]));
  const auto c = g.voxel_center(sv.ijk[0], sv.ijk[1], sv.ijk[2]);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(w[k], c[k], 1e-5);
  const openvdb::Coord ijk(sv.ijk[0], sv.ijk[1], sv.ijk[2]);
  auto albedo = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find("albedo"));
  auto direct = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find("direct"));
  auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(find("density"));
  auto aniso = openvdb::gridPtrCast<openvdb::FloatGrid>(find("aniso_ny"));
  EXPECT_EQ(albedo->tree().getValue(ijk)[0], sv.albedo[0]);
  EXPECT_EQ(direct->tree().getValue(ijk)[1], sv.direct[1]);
  EXPECT_EQ(density->tree().getValue(ijk), sv.coverage);
  EXPECT_EQ(aniso->tree().getValue(ijk), sv.aniso[3]);
  EXPECT_EQ(albedo->activeVoxelCount(), g.surface.size());
  auto sdf = openvdb::gridPtrCast<openvdb::FloatGrid>(find("sdf"));
  EXPECT_EQ(sdf->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_EQ(sdf->activeVoxelCount(), g.sdf.size());
  EXPECT_EQ(sdf->tree().getValue(openvdb::Coord(2, 3, 4)), g.sdf[size_t(g.linear(2, 3, 4))]);
  auto interior = openvdb::gridPtrCast<openvdb::FloatGrid>(find("interior"));
  EXPECT_EQ(interior->activeVoxelCount(), test::count_space(g, VoxelSpace::Interior));
  EXPECT_GT(interior->activeVoxelCount(), 0u);
  auto lpv = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find("lpv_r"));
  ASSERT_TRUE(lpv);
  EXPECT_EQ(lpv->tree().getValue(openvdb::Coord(1, 2, 3))[1], 7.f);
  EXPECT_EQ(lpv->activeVoxelCount(), 1u);
  const openvdb::Vec3d lw = lpv->transform().indexToWorld(openvdb::Coord(1, 2, 3));
  EXPECT_NEAR(lw[0], -1.0 + 1.5 * 0.5, 1e-6);
  if (std::system("command -v vdb_print > /dev/null 2>&1") == 0) {
    EXPECT_EQ(std::system(("vdb_print -l '" + path + "' > /dev/null 2>&1").c_str()), 0);
  }
}

TEST(VoxelVdb, RefusesBadExtraGridsMissingFoldersAndInputs) {
  Scene s;
  const int m = test::add_material(s, 0.7f);
  test::add_box(s, {0, 0, 0}, {1, 1, 1}, false, m);
  VoxelSettings vs;
  vs.resolution = 8;
  VoxelGrid g;
  ASSERT_TRUE(voxelize(s, vs, Context{}, g).is_ok());
  DenseGridExport e;
  e.name = "sdf";  // taken
  e.voxel_size = 1.f;
  e.dims = {1, 1, 1};
  e.values = {1.f};
  const std::string path = scratch("bad.vdb");
  EXPECT_EQ(write_voxels_vdb(path, g, {e}, {}).code(), ExitCode::BadArguments);
  e.name = "x";
  e.values = {1.f, 2.f};
  EXPECT_EQ(write_voxels_vdb(path, g, {e}, {}).code(), ExitCode::BadArguments);
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_EQ(write_voxels_vdb(scratch("missing/dir/x.vdb"), g, {}, {}).code(), ExitCode::IoFailure);
  ASSERT_TRUE(write_voxels_vdb(path, g, {}, {}).is_ok());
  VoxelVdbOptions o;
  o.inputs = {path};  // never over an input
  EXPECT_NE(write_voxels_vdb(path, g, {}, o).code(), ExitCode::Ok);
}

}  // namespace
}  // namespace gibake
