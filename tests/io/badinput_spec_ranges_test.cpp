// Values outside glTF's own ranges: refused where the file means nothing (a light's range of 0),
// otherwise brought into the range, or left out, and said so in a warning naming the place.
#include <string>

#include "tests/io/import_testutil.h"

namespace gibake::test {
namespace {

GltfBuilder cube() {
  GltfBuilder g;
  int m = add_unit_cube_mesh(g);
  g.node({{"mesh", m}});
  return g;
}

bool warned(const ImportResult& r, const std::string& text) {
  for (const std::string& w : r.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

// The cube with one KHR_lights_punctual light, placed by a second node.
GltfBuilder cube_with_light(const json& light) {
  GltfBuilder g = cube();
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({light});
  g.doc["nodes"].push_back({{"translation", {0, 3, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  g.doc["scenes"][0]["nodes"].push_back(1);
  return g;
}

// tinygltf reads an absent range and 0 alike ("no range"); a range of 0 given is refused, as a
// negative one is.
TEST(BadInputSpecRanges, LightRangeOfZeroIsRefused) {
  TempDir dir;
  const ImportResult zero =
      import_file(cube_with_light({{"type", "point"}, {"intensity", 10}, {"range", 0}}).write(dir, "zero"));
  ASSERT_FALSE(zero.status.is_ok());
  EXPECT_EQ(zero.status.code(), ExitCode::InvalidInput);
  EXPECT_EQ(zero.status.where(), "extensions.KHR_lights_punctual.lights[0].range") << zero.status.message();
  EXPECT_NE(zero.status.what().find("0 is not above 0"), std::string::npos) << zero.status.message();
  const ImportResult absent = import_file(cube_with_light({{"type", "point"}, {"intensity", 10}}).write(dir, "none"));
  ASSERT_TRUE(absent.status.is_ok()) << absent.status.message();
  EXPECT_EQ(absent.scene.lights.at(0).range, 0.f);  // no range
  // A directional light does not use a range: reported, not refused.
  const ImportResult sun =
      import_file(cube_with_light({{"type", "directional"}, {"intensity", 10}, {"range", 0}}).write(dir, "sun"));
  ASSERT_TRUE(sun.status.is_ok()) << sun.status.message();
  EXPECT_TRUE(warned(sun, "lights[0].range: 0 is not above 0; a directional light has no range, ignored"));
}

// 0 <= inner < outer <= pi/2: an outer cone past a hemisphere becomes one, an inner cone wider
// than the outer becomes the outer (a hard edge), and an outer cone of 0 is a light said to be dark.
TEST(BadInputSpecRanges, SpotConesAreBroughtIntoTheirRange) {
  TempDir dir;
  const json spot = {{"type", "spot"}, {"intensity", 10}, {"spot", {{"innerConeAngle", 0.7}, {"outerConeAngle", 0.3}}}};
  const ImportResult r = import_file(cube_with_light(spot).write(dir, "inner"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_FLOAT_EQ(r.scene.lights.at(0).inner_cone_angle, 0.3f);
  EXPECT_FLOAT_EQ(r.scene.lights.at(0).outer_cone_angle, 0.3f);
  EXPECT_TRUE(warned(r,
                     "lights[0].spot.innerConeAngle: 0.7 rad is outside 0 <= innerConeAngle < outerConeAngle <= "
                     "pi/2; 0.3 used"));
  const json wide = {{"type", "spot"}, {"intensity", 10}, {"spot", {{"outerConeAngle", 3.0}}}};
  const ImportResult w = import_file(cube_with_light(wide).write(dir, "wide"));
  ASSERT_TRUE(w.status.is_ok()) << w.status.message();
  EXPECT_FLOAT_EQ(w.scene.lights.at(0).outer_cone_angle, 1.5707964f);
  EXPECT_TRUE(warned(w, "lights[0].spot.outerConeAngle: 3 rad is outside"));
  // No cone at all: kept, one line says the light gives none.
  const json shut = {{"type", "spot"}, {"intensity", 10}, {"spot", {{"innerConeAngle", 0.0}, {"outerConeAngle", 0.0}}}};
  const ImportResult s = import_file(cube_with_light(shut).write(dir, "shut"));
  ASSERT_TRUE(s.status.is_ok()) << s.status.message();
  EXPECT_EQ(s.scene.lights.at(0).outer_cone_angle, 0.f);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_TRUE(warned(s, "lights[0].spot.outerConeAngle: 0 rad is not above 0; the spot light gives no light"));
  const json fine = {{"type", "spot"}, {"intensity", 10}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.4}}}};
  const ImportResult f = import_file(cube_with_light(fine).write(dir, "fine"));
  ASSERT_TRUE(f.status.is_ok());
  EXPECT_TRUE(f.warnings.empty()) << f.warnings.front();
}

// Colours glTF bounds below by 0: a negative one reads as 0, and is said to.
TEST(BadInputSpecRanges, NegativeColoursReadAsZeroAndAreReported) {
  TempDir dir;
  GltfBuilder g = cube_with_light({{"type", "point"}, {"intensity", 10}, {"color", {-1.0, 0.5, 1.0}}});
  g.doc["materials"] = json::array({{{"emissiveFactor", {0.5, -2.0, 1.0}}}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  const ImportResult r = import_file(g.write(dir, "negative"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.lights.at(0).color[0], 0.f);
  EXPECT_EQ(r.scene.lights.at(0).color[1], 0.5f);
  EXPECT_EQ(r.scene.materials.at(0).emissive[1], 0.f);
  EXPECT_EQ(r.scene.materials.at(0).emissive[0], 0.5f);
  EXPECT_TRUE(warned(r, "lights[0].color[0]: -1 is below 0; 0 used"));
  EXPECT_TRUE(warned(r, "materials[0].emissiveFactor[1]: -2 is below 0; 0 used"));
}

// An alphaMode glTF does not name (the enum is case-sensitive) is read as OPAQUE, and a negative
// emissiveStrength or a transmissionFactor outside 0..1 brought into range; each is reported.
TEST(BadInputSpecRanges, MaterialEnumsAndStrengthsOutsideTheSpecAreReported) {
  TempDir dir;
  GltfBuilder g = cube();
  g.doc["materials"] = json::array({{{"alphaMode", "mask"},
                                     {"emissiveFactor", {1.0, 1.0, 1.0}},
                                     {"extensions",
                                      {{"KHR_materials_emissive_strength", {{"emissiveStrength", -3.0}}},
                                       {"KHR_materials_transmission", {{"transmissionFactor", 1.5}}}}}}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  const ImportResult r = import_file(g.write(dir, "materials"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  const Material& m = r.scene.materials.at(0);
  EXPECT_EQ(m.alpha_mode, AlphaMode::Opaque);
  EXPECT_EQ(m.emissive_strength, 0.f);
  EXPECT_EQ(m.transmission, 1.f);
  EXPECT_TRUE(warned(r, "materials[0].alphaMode: 'mask' is not OPAQUE, MASK or BLEND; OPAQUE used"));
  EXPECT_TRUE(warned(r, "KHR_materials_emissive_strength.emissiveStrength: -3 is below 0; 0 used"));
  EXPECT_TRUE(warned(r, "KHR_materials_transmission.transmissionFactor: 1.5 is outside 0..1; 1 used"));
}

// KHR_materials_unlit is read (a required one does not stop the import) but not modelled: the
// surface reflects light as a diffuse one of its base colour, and the import says so.
TEST(BadInputSpecRanges, UnlitMaterialIsReportedAsLit) {
  TempDir dir;
  GltfBuilder g = cube();
  g.doc["materials"] = json::array({{{"extensions", {{"KHR_materials_unlit", json::object()}}}}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  g.doc["extensionsUsed"] = {"KHR_materials_unlit"};
  g.doc["extensionsRequired"] = {"KHR_materials_unlit"};
  const ImportResult r = import_file(g.write(dir, "unlit"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_TRUE(warned(r, "KHR_materials_unlit is not supported (1 material, materials[0]): lit as a diffuse surface"));
}

TEST(BadInputSpecRanges, CameraAspectOfZeroIsReported) {
  TempDir dir;
  GltfBuilder g = cube();
  g.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"aspectRatio", 0}, {"znear", 0.1}}}}};
  g.doc["nodes"].push_back({{"camera", 0}, {"translation", {0, 0, 4}}});
  g.doc["scenes"][0]["nodes"].push_back(1);
  const ImportResult r = import_file(g.write(dir, "aspect"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  ASSERT_EQ(r.scene.cameras.size(), 1u);
  EXPECT_TRUE(warned(r, "cameras[0].perspective.aspectRatio: 0 is not above 0; the view's own aspect used"));
}

// An image in a bufferView names image/png or image/jpeg; the bytes decide what it is read as.
TEST(BadInputSpecRanges, ImageMimeTypesAreReported) {
  TempDir dir;
  GltfBuilder g = cube();
  g.doc["images"] = {{{"bufferView", 0}, {"mimeType", "text/plain"}}, {{"bufferView", 0}}};
  const ImportResult r = import_file(g.write(dir, "mime"));
  EXPECT_TRUE(warned(r, "images[0].mimeType: \"text/plain\" is not image/png or image/jpeg; decoded by its bytes"));
  EXPECT_TRUE(warned(r, "images[1]: an image in a bufferView has no mimeType"));
}

// glTF allows a scale of 0 (it hides a node); such a node's mesh is left out, the rest placed.
TEST(BadInputSpecRanges, FlattenedMeshNodeIsLeftOut) {
  TempDir dir;
  GltfBuilder g = cube();
  g.doc["nodes"].push_back({{"mesh", 0}, {"scale", {0, 1, 1}}});
  g.doc["nodes"].push_back({{"mesh", 0}, {"matrix", {1, 0, 0, 0, 2, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}});
  g.doc["scenes"][0]["nodes"] = {0, 1, 2};
  const ImportResult r = import_file(g.write(dir, "flat"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 12u);  // the one cube
  // One line for them all, naming the first.
  EXPECT_TRUE(warned(r,
                     "nodes[1] and 1 more mesh nodes: a scale of 0 flattens them (the world matrix is not "
                     "invertible); left out"));
  EXPECT_EQ(r.warnings.size(), 1u);
  GltfBuilder only = cube();
  only.doc["nodes"][0]["scale"] = {1, 1, 0};
  const ImportResult none = import_file(only.write(dir, "only"));
  ASSERT_FALSE(none.status.is_ok());
  EXPECT_NE(none.status.what().find("scene has no triangles"), std::string::npos) << none.status.message();
}

// Draco positions far outside POSITION's min/max: the stream and the accessor disagree. Placed as
// decoded, and said so.
TEST(BadInputSpecRanges, DracoPositionsOutsideTheAccessorBoxAreReported) {
  TempDir dir;
  const std::string bin = read_file(asset("draco/box/Box.bin"));
  json d = json::parse(read_file(asset("draco/box/Box.gltf")));
  write_file(dir.file("Box.bin"), bin);
  write_file(dir.file("Box.gltf"), d.dump());
  const ImportResult fine = import_file(dir.file("Box.gltf"));
  ASSERT_TRUE(fine.status.is_ok()) << fine.status.message();
  EXPECT_FALSE(warned(fine, "outside the POSITION accessor's min/max"));
  d["accessors"][2]["min"] = {-0.1, -0.1, -0.1};
  d["accessors"][2]["max"] = {0.1, 0.1, 0.1};
  write_file(dir.file("Box.gltf"), d.dump());
  const ImportResult r = import_file(dir.file("Box.gltf"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_TRUE(warned(r,
                     "KHR_draco_mesh_compression: decoded positions span -0.5..0.5 on axis x, outside the POSITION "
                     "accessor's min/max -0.1..0.1"));
}

}  // namespace
}  // namespace gibake::test
