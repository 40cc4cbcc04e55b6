// KHR_materials_transmission on import: transmissionFactor read into Material::transmission
// (clamped to 0..1) and transmissionTexture (decoded), one warning saying glass is traced as thin
// pass-through and what is not read.
#include <gtest/gtest.h>

#include "import_testutil.h"

using namespace gibake;
using namespace gibake::test;

namespace {

size_t warnings_naming(const ImportResult& r, const std::string& what) {
  size_t n = 0;
  for (const std::string& w : r.warnings) n += w.find(what) != std::string::npos;
  return n;
}

}  // namespace

TEST(TransmissionImport, FactorIsReadAndTheWarningSaysHowGlassIsTraced) {
  // The lamp's paper shade (materials[2]): transmissionFactor 1 with a transmission texture.
  const ImportResult lamp = import_file(asset("lights-punctual-lamp/LightsPunctualLamp.gltf"));
  ASSERT_TRUE(lamp.status.is_ok()) << lamp.status.message();
  ASSERT_EQ(lamp.scene.materials.size(), 3u);
  EXPECT_EQ(lamp.scene.materials[0].transmission, 0.f);
  EXPECT_EQ(lamp.scene.materials[2].transmission, 1.f);
  EXPECT_EQ(warnings_naming(lamp, "KHR_materials_transmission"), 1u);
  EXPECT_EQ(warnings_naming(lamp, "KHR_materials_transmission is partly supported (1 material, materials[2]): traced "
                                  "as thin pass-through glass"),
            1u);
  EXPECT_EQ(warnings_naming(lamp, "no refraction, IOR or roughness"), 1u);
  EXPECT_EQ(lamp.scene.materials[2].transmission_texture.texture, 6);
  const Texture& map = lamp.scene.textures[6];  // decoded (its red channel is read), unlike normal maps
  EXPECT_EQ(map.rgba8.size(), size_t(map.width) * size_t(map.height) * 4);
  EXPECT_GT(map.width, 0);
}

TEST(TransmissionImport, FactorOutOfRangeIsClamped) {
  TempDir dir;
  for (const auto& [factor, expected] :
       {std::pair<json, float>{0.5, 0.5f}, {1.7, 1.f}, {-0.3, 0.f}, {"x", 0.f}}) {
    GltfBuilder g;
    const int mesh = add_unit_cube_mesh(g, {{"material", 0}});
    g.node({{"mesh", mesh}});
    g.doc["materials"] = json::array({{{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", factor}}}}}}});
    const ImportResult r = import_file(g.write(dir, "glass"));
    ASSERT_TRUE(r.status.is_ok()) << r.status.message();
    ASSERT_EQ(r.scene.materials.size(), 1u);
    EXPECT_EQ(r.scene.materials[0].transmission, expected) << factor.dump();
  }
}
