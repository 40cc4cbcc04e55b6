// Every shared asset with a triangle count in ../shared/assets/SOURCES.md imports with exactly
// that many triangles (after node instancing); the bundled sample scene imports as described in
// samples/README.md.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "io/gltf/import.h"
#include "io/inspect/inspect_report.h"
#include "io/inspect/mesh_diagnostics.h"

namespace gibake {
namespace {

struct AssetCount {
  const char* path;  // relative to GIBAKE_ASSETS_DIR
  uint64_t triangles;
};

// From SOURCES.md, "triangles" column (the first number: as placed by the default scene).
const AssetCount kAssets[] = {
    {"sponza/Sponza.gltf", 262249},
    {"cornell-box-nvpro/cornellBox.gltf", 16732},
    {"reciprocating-saw/ReciprocatingSaw.gltf", 198470},
    {"glb/ReciprocatingSaw.glb", 198470},
    {"glb/NormalTangentTest.glb", 7774},
    {"toy-car/ToyCar.gltf", 108936},
    {"lights-punctual-lamp/LightsPunctualLamp.gltf", 6000},
    {"lights-sphere/sphere_lights.gltf", 224},
    {"emissive-strength-test/EmissiveStrengthTest.gltf", 90},
    {"emissive-strength-test/glb/EmissiveStrengthTest.glb", 90},
    {"texture-transform-test/TextureTransformTest.gltf", 24},
    {"alpha-blend-mode-test/AlphaBlendModeTest.gltf", 61},
    {"box/Box.gltf", 12},
    {"draco/box/Box.gltf", 12},
    {"draco/avocado/Avocado.gltf", 682},
    {"draco/waterbottle/WaterBottle.gltf", 4510},
    {"draco/cesiummilktruck/CesiumMilkTruck.gltf", 3624},
    {"draco/2cylinderengine/2CylinderEngine.gltf", 110336},
    {"draco/box_google/Box_Draco.glb", 12},
    {"draco/boxmeta_google/BoxMetaDraco.gltf", 12},
};

std::string asset(const std::string& relative) {
  return std::string(GIBAKE_ASSETS_DIR) + "/" + relative;
}

// 262249 -> "262,249", as SOURCES.md writes counts.
std::string with_commas(uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string file_name(const std::string& path) { return path.substr(path.rfind('/') + 1); }

void PrintTo(const AssetCount& a, std::ostream* os) { *os << a.path << " (" << a.triangles << ")"; }

class AssetTriangles : public ::testing::TestWithParam<AssetCount> {};

TEST_P(AssetTriangles, ImportsWithExpectedCount) {
  const AssetCount& a = GetParam();
  ImportOptions options;
  options.load_textures = false;
  std::vector<std::string> warnings;
  Context ctx;
  ctx.warn = [&warnings](const std::string& m) { warnings.push_back(m); };
  Scene scene;
  const Status st = import_scene(asset(a.path), options, ctx, scene);
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_EQ(scene.triangle_count(), a.triangles) << a.path;
  EXPECT_EQ(scene.tri_material.size(), scene.triangle_count());
  EXPECT_EQ(scene.positions.size(), scene.vertex_count() * 3);
  EXPECT_FALSE(scene.bounds.empty());
  uint64_t placed = 0;
  for (const PrimitiveInstance& inst : scene.instances) placed += inst.triangle_count;
  EXPECT_EQ(placed, a.triangles) << "instances do not cover the triangles";
}

INSTANTIATE_TEST_SUITE_P(SharedAssets, AssetTriangles, ::testing::ValuesIn(kAssets),
                         [](const ::testing::TestParamInfo<AssetCount>& info) {
                           std::string name;
                           for (const char* c = info.param.path; *c; ++c)
                             name += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
                           return name;
                         });

// The list above stays in step with SOURCES.md: each file and its count is written there.
TEST(AssetList, MatchesSourcesMd) {
  const std::string sources = read_text(asset("SOURCES.md"));
  ASSERT_FALSE(sources.empty()) << "cannot read " << asset("SOURCES.md");
  for (const AssetCount& a : kAssets) {
    const std::string name = file_name(a.path);
    const bool named = sources.find(name) != std::string::npos ||
                       sources.find("*.gltf") != std::string::npos;  // the draco row
    EXPECT_TRUE(named) << name;
    EXPECT_NE(sources.find(with_commas(a.triangles)), std::string::npos) << a.path;
    std::ifstream probe(asset(a.path), std::ios::binary);
    EXPECT_TRUE(probe.good()) << "missing " << a.path;
  }
}

// samples/cornell as samples/README.md describes it.
TEST(SampleScene, CornellImportsAsDocumented) {
  const std::string path = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  InspectResult r;
  InspectOptions options;
  options.check_self_intersections = true;
  const Status st = inspect_scene(path, options, Context{}, r);
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_EQ(r.scene.triangle_count(), 36u);
  EXPECT_EQ(r.scene.stats.meshes, 3u);
  EXPECT_EQ(r.scene.stats.cameras, 1u);
  ASSERT_EQ(r.scene.lights.size(), 1u);
  EXPECT_EQ(r.scene.lights[0].type, Light::Type::Point);
  EXPECT_FLOAT_EQ(r.scene.lights[0].intensity, 3.0f);
  ASSERT_EQ(r.scene.materials.size(), 4u);
  int emissive = 0;
  for (const Material& m : r.scene.materials) {
    if (!m.is_emissive()) continue;
    ++emissive;
    EXPECT_FLOAT_EQ(m.emissive[0] * m.emissive_strength, 10.0f);
  }
  EXPECT_EQ(emissive, 1);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r.scene.bounds.min[i], i == 1 ? 0.f : -1.f, 1e-6f);
    EXPECT_NEAR(r.scene.bounds.max[i], i == 1 ? 2.f : 1.f, 1e-6f);
  }
  const MeshDiagnostics& d = r.diagnostics;
  EXPECT_EQ(d.components, 4u);
  EXPECT_EQ(d.closed_components, 2u);
  EXPECT_EQ(d.inward_closed_components, 0u);
  EXPECT_EQ(d.border_edges, 8u);
  EXPECT_EQ(d.non_manifold_edges, 0u);
  EXPECT_EQ(d.inconsistent_edges, 0u);
  EXPECT_EQ(d.degenerate_triangles, 0u);
  EXPECT_EQ(d.self_intersecting_pairs, 0u);
  // The two boxes are solids: their centres are inside, the room's middle is not.
  const ClosedMeshInsideTester tester(r.scene);
  EXPECT_EQ(tester.component_count(), 2u);
  const float short_box[3] = {0.35f, 0.3f, 0.3f}, tall_box[3] = {-0.33f, 0.6f, -0.3f};
  const float air[3] = {0.f, 1.5f, 0.5f};
  EXPECT_EQ(tester.classify(short_box), 1);
  EXPECT_EQ(tester.classify(tall_box), 1);
  EXPECT_EQ(tester.classify(air), -1);
}

}  // namespace
}  // namespace gibake
