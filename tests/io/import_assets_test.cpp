// Import spot checks on the shared real-world assets.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "tests/io/import_testutil.h"

namespace gibake::test {
namespace {

TEST(ImportAssets, BoxHasTwelveTrianglesAndUnitBounds) {
  auto r = import_file(asset("box/Box.gltf"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 12u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(r.scene.bounds.min[size_t(k)], -0.5f, 1e-6);
    EXPECT_NEAR(r.scene.bounds.max[size_t(k)], 0.5f, 1e-6);
  }
  EXPECT_EQ(r.scene.materials.size(), 1u);
  EXPECT_EQ(r.scene.tri_material[0], 0);
  EXPECT_EQ(r.scene.normals.size(), r.scene.positions.size());
  EXPECT_EQ(r.scene.uvs.size(), r.scene.vertex_count() * 2);
  EXPECT_TRUE(r.scene.colors.empty());
  ASSERT_EQ(r.scene.instances.size(), 1u);
  EXPECT_FALSE(r.scene.instances[0].mirrored);
  EXPECT_EQ(r.scene.stats.meshes, 1u);
  EXPECT_EQ(r.scene.stats.nodes, 2u);
  EXPECT_EQ(r.scene.source_path, asset("box/Box.gltf"));
  ASSERT_EQ(r.scene.input_files.size(), 2u);  // Box.gltf, Box0.bin
  EXPECT_NE(r.scene.input_files[1].find("Box0.bin"), std::string::npos);
}

TEST(ImportAssets, GlbLoads) {
  auto r = import_file(asset("glb/NormalTangentTest.glb"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 7774u);
  ASSERT_FALSE(r.scene.textures.empty());
  EXPECT_GT(r.scene.textures[0].width, 0);
  EXPECT_EQ(r.scene.textures[0].rgba8.size(), size_t(r.scene.textures[0].width) * r.scene.textures[0].height * 4);
}

TEST(ImportAssets, EmissiveStrengthGltfAndGlb) {
  for (const char* f : {"emissive-strength-test/EmissiveStrengthTest.gltf",
                        "emissive-strength-test/glb/EmissiveStrengthTest.glb"}) {
    auto r = import_file(asset(f));
    ASSERT_TRUE(r.status.is_ok()) << r.status.message();
    EXPECT_EQ(r.scene.triangle_count(), 90u) << f;
    ASSERT_EQ(r.scene.materials.size(), 6u);
    EXPECT_EQ(r.scene.materials[0].name, "Emit4");
    EXPECT_FLOAT_EQ(r.scene.materials[0].emissive_strength, 4.f);
    EXPECT_FLOAT_EQ(r.scene.materials[4].emissive_strength, 8.f);
    EXPECT_FLOAT_EQ(r.scene.materials[3].emissive_strength, 1.f);
    EXPECT_FLOAT_EQ(r.scene.materials[0].emissive[2], 0.9f);
    EXPECT_TRUE(r.scene.materials[0].is_emissive());
    EXPECT_FALSE(r.scene.materials[1].is_emissive());
  }
}

TEST(ImportAssets, TextureTransformValues) {
  auto r = import_file(asset("texture-transform-test/TextureTransformTest.gltf"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 24u);
  const auto& m = r.scene.materials;
  ASSERT_GE(m.size(), 9u);
  EXPECT_TRUE(m[0].base_color_texture.has_transform);
  EXPECT_FLOAT_EQ(m[0].base_color_texture.offset[0], 0.5f);
  EXPECT_FLOAT_EQ(m[1].base_color_texture.offset[1], 0.5f);
  EXPECT_NEAR(m[3].base_color_texture.rotation, 0.39269908f, 1e-6);
  EXPECT_FLOAT_EQ(m[4].base_color_texture.scale[0], 1.5f);
  EXPECT_FLOAT_EQ(m[5].base_color_texture.offset[0], -0.2f);
  EXPECT_FLOAT_EQ(m[5].base_color_texture.rotation, 0.3f);
  EXPECT_FALSE(m[6].base_color_texture.has_transform);
  EXPECT_GE(m[0].base_color_texture.texture, 0);
}

TEST(ImportAssets, AlphaModes) {
  auto r = import_file(asset("alpha-blend-mode-test/AlphaBlendModeTest.gltf"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 61u);
  const auto& m = r.scene.materials;
  ASSERT_EQ(m.size(), 6u);
  EXPECT_EQ(m[0].alpha_mode, AlphaMode::Opaque);
  EXPECT_EQ(m[1].alpha_mode, AlphaMode::Blend);
  EXPECT_EQ(m[2].alpha_mode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(m[2].alpha_cutoff, 0.25f);
  EXPECT_FLOAT_EQ(m[3].alpha_cutoff, 0.75f);
  EXPECT_FLOAT_EQ(m[4].alpha_cutoff, 0.5f);
  EXPECT_TRUE(m[1].double_sided);
  EXPECT_FALSE(m[0].double_sided);
}

TEST(ImportAssets, PunctualLightsLamp) {
  auto r = import_file(asset("lights-punctual-lamp/LightsPunctualLamp.gltf"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 6000u);
  EXPECT_EQ(r.scene.lights.size(), 5u);
  for (const auto& l : r.scene.lights) {
    EXPECT_EQ(l.type, Light::Type::Point);
    float len = std::sqrt(l.direction[0] * l.direction[0] + l.direction[1] * l.direction[1] +
                          l.direction[2] * l.direction[2]);
    EXPECT_NEAR(len, 1.f, 1e-5);
  }
  bool has180 = false;
  for (const auto& l : r.scene.lights) has180 = has180 || l.intensity == 180.f;
  EXPECT_TRUE(has180);
}

TEST(ImportAssets, DracoFilesDecode) {
  struct Case { const char* file; size_t tris; };
  for (Case c : {Case{"draco/box/Box.gltf", 12}, Case{"draco/avocado/Avocado.gltf", 682},
                 Case{"draco/box_google/Box_Draco.glb", 12},
                 Case{"draco/cesiummilktruck/CesiumMilkTruck.gltf", 3624}}) {
    auto r = import_file(asset(c.file));
    ASSERT_TRUE(r.status.is_ok()) << c.file << ": " << r.status.message();
    EXPECT_EQ(r.scene.triangle_count(), c.tris) << c.file;
    EXPECT_GE(r.scene.stats.draco_primitives, 1u) << c.file;
    ASSERT_FALSE(r.scene.instances.empty());
    EXPECT_TRUE(r.scene.instances[0].draco);
  }
}

TEST(ImportAssets, LegacyDracoIsRefused) {
  for (const char* f : {"draco-legacy-2017/box/Box.gltf", "draco-legacy-2017/boxtextured/BoxTextured.gltf"}) {
    auto r = import_file(asset(f));
    ASSERT_FALSE(r.status.is_ok()) << f;
    EXPECT_EQ(r.status.code(), ExitCode::InvalidInput);
    EXPECT_NE(r.status.where().find("KHR_draco_mesh_compression"), std::string::npos) << r.status.message();
    EXPECT_TRUE(r.scene.positions.empty());
  }
}

// Sorted triangle centroids, for comparing meshes whose vertex order differs.
std::vector<std::array<float, 3>> centroids(const Scene& s) {
  std::vector<std::array<float, 3>> c;
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    std::array<float, 3> m{0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) m[size_t(a)] += s.positions[3 * size_t(s.indices[3 * t + size_t(k)]) + size_t(a)] / 3.f;
    c.push_back(m);
  }
  std::sort(c.begin(), c.end());
  return c;
}

TEST(ImportAssets, DracoBoxMatchesPlainBox) {
  auto plain = import_file(asset("box/Box.gltf"));
  auto draco = import_file(asset("draco/box/Box.gltf"));
  ASSERT_TRUE(plain.status.is_ok() && draco.status.is_ok()) << draco.status.message();
  ASSERT_EQ(plain.scene.triangle_count(), draco.scene.triangle_count());
  // Positions quantized to 11 bits (the Draco default for glTF-Pipeline) over a 1 m extent,
  // plus the accessor's 1.0009 scale: allow 2/2^11 of the extent.
  const float tol = 2.f / 2048.f + 1e-3f;
  auto a = centroids(plain.scene), b = centroids(draco.scene);
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[i][size_t(k)], b[i][size_t(k)], tol) << i;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(plain.scene.bounds.min[size_t(k)], draco.scene.bounds.min[size_t(k)], tol);
    EXPECT_NEAR(plain.scene.bounds.max[size_t(k)], draco.scene.bounds.max[size_t(k)], tol);
  }
}

TEST(ImportAssets, CornellBoxWithBrokenTextureReferenceStillImports) {
  auto r = import_file(asset("cornell-box-nvpro/cornellBox.gltf"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 16732u);
  EXPECT_FALSE(r.warnings.empty());  // textures[0] names a missing image
  float max_emissive = 0.f;
  for (const auto& m : r.scene.materials) max_emissive = std::max(max_emissive, m.emissive[0]);
  EXPECT_FLOAT_EQ(max_emissive, 10.f);
}

TEST(ImportAssets, MoreSharedScenes) {
  struct Case { const char* file; size_t tris, lights; };
  for (Case c : {Case{"lights-sphere/sphere_lights.gltf", 224, 4}, Case{"toy-car/ToyCar.gltf", 108936, 0},
                 Case{"draco/2cylinderengine/2CylinderEngine.gltf", 110336, 0},
                 Case{"draco/waterbottle/WaterBottle.gltf", 4510, 0}}) {
    auto r = import_file(asset(c.file));
    ASSERT_TRUE(r.status.is_ok()) << c.file << ": " << r.status.message();
    EXPECT_EQ(r.scene.triangle_count(), c.tris) << c.file;
    EXPECT_EQ(r.scene.lights.size(), c.lights) << c.file;
    EXPECT_EQ(r.scene.instances.empty(), false);
  }
}

// Images are decoded in parallel after parsing: with every thread the pixels (and warnings) must be
// exactly those of a one-thread import. External PNG files and PNGs in GLB bufferViews.
TEST(ImportAssets, ParallelTextureDecodeMatchesSerial) {
  for (const char* file : {"toy-car/ToyCar.gltf", "glb/NormalTangentTest.glb"}) {
    auto serial = import_file(asset(file), {}, 1);
    auto parallel = import_file(asset(file), {}, 0);
    ASSERT_TRUE(serial.status.is_ok()) << file << ": " << serial.status.message();
    ASSERT_TRUE(parallel.status.is_ok()) << file << ": " << parallel.status.message();
    EXPECT_EQ(serial.warnings, parallel.warnings) << file;
    ASSERT_GE(serial.scene.textures.size(), 3u) << file;
    ASSERT_EQ(serial.scene.textures.size(), parallel.scene.textures.size()) << file;
    size_t decoded = 0;
    for (size_t t = 0; t < serial.scene.textures.size(); ++t) {
      const Texture& a = serial.scene.textures[t];
      const Texture& b = parallel.scene.textures[t];
      EXPECT_GT(a.width, 0) << file << " texture " << t;
      // Maps no material reads for base colour or emission are not decoded (no pixels).
      if (!a.rgba8.empty()) {
        ++decoded;
        EXPECT_EQ(a.rgba8.size(), size_t(a.width) * size_t(a.height) * 4) << file << " texture " << t;
      }
      EXPECT_EQ(a.width, b.width) << file << " texture " << t;
      EXPECT_EQ(a.height, b.height) << file << " texture " << t;
      EXPECT_TRUE(a.rgba8 == b.rgba8) << file << " texture " << t << " pixels differ";
    }
    EXPECT_GE(decoded, 1u) << file;
  }
}

// ImportOptions::cancelled stops the import (the bake sets it when the driver lists no device for
// --backend vulkan): the import fails naming the file, leaves no scene, and decodes no images after
// the flag is set; the flag only ever read false leaves the import as it was.
TEST(ImportAssets, CancelledImportStopsWithoutAScene) {
  std::atomic<int> polls{0};
  ImportOptions cancel;
  cancel.cancelled = [&polls] {
    ++polls;
    return true;
  };
  auto r = import_file(asset("toy-car/ToyCar.gltf"), cancel);
  ASSERT_FALSE(r.status.is_ok());
  EXPECT_NE(r.status.message().find("import cancelled"), std::string::npos) << r.status.message();
  EXPECT_NE(r.status.message().find("ToyCar.gltf"), std::string::npos) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 0u);
  EXPECT_TRUE(r.scene.textures.empty());
  EXPECT_GT(polls.load(), 0);
  ImportOptions never;
  never.cancelled = [] { return false; };
  auto plain = import_file(asset("toy-car/ToyCar.gltf"));
  auto polled = import_file(asset("toy-car/ToyCar.gltf"), never);
  ASSERT_TRUE(polled.status.is_ok()) << polled.status.message();
  EXPECT_EQ(polled.scene.positions, plain.scene.positions);
  ASSERT_EQ(polled.scene.textures.size(), plain.scene.textures.size());
  for (size_t t = 0; t < plain.scene.textures.size(); ++t)
    EXPECT_TRUE(polled.scene.textures[t].rgba8 == plain.scene.textures[t].rgba8) << "texture " << t;
}

TEST(ImportAssets, SponzaImportsWithInstancingAndCameras) {
  ImportOptions opt;
  opt.load_textures = false;
  auto r = import_file(asset("sponza/Sponza.gltf"), opt);
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 262249u);
  EXPECT_EQ(r.scene.stats.cameras, 4u);
  EXPECT_TRUE(r.scene.lights.empty());
  EXPECT_FALSE(r.scene.bounds.empty());
}

}  // namespace
}  // namespace gibake::test
