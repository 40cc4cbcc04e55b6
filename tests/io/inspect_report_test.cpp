// The inspect report built from a hand-made Scene: JSON fields, units, and always-valid output.
#include "io/inspect/inspect_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace gibake {
namespace {

using nlohmann::json;

Scene small_scene() {
  Scene s;
  s.source_path = "scene.gltf";
  s.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  s.indices = {0, 1, 2};
  s.tri_material = {1};
  for (int i = 0; i < 3; ++i)
    s.bounds.extend({s.positions[i * 3], s.positions[i * 3 + 1], s.positions[i * 3 + 2]});
  s.stats.meshes = 1;
  s.stats.nodes = 2;
  s.stats.primitives = 1;
  s.stats.draco_primitives = 1;
  s.stats.skipped_primitives = 3;
  s.stats.cameras = 2;
  s.materials.resize(2);
  s.materials[0].name = "plain";
  Material& lamp = s.materials[1];
  lamp.name = "lamp";
  lamp.emissive[0] = 1.f;
  lamp.emissive[1] = 0.5f;
  lamp.emissive_strength = 10.f;
  lamp.alpha_mode = AlphaMode::Mask;
  lamp.alpha_cutoff = 0.25f;
  lamp.double_sided = true;
  lamp.emissive_texture.texture = 0;
  lamp.emissive_texture.has_transform = true;
  lamp.emissive_texture.scale[0] = 2.f;
  s.textures.resize(1);
  s.textures[0].name = "glow.png";
  s.textures[0].width = 64;
  s.textures[0].height = 32;
  Light sun;
  sun.type = Light::Type::Directional;
  sun.intensity = 100000.f;
  Light spot;
  spot.type = Light::Type::Spot;
  spot.intensity = 50.f;
  spot.range = 4.f;
  spot.position = {1, 2, 3};
  s.lights = {sun, spot};
  return s;
}

TEST(InspectReport, JsonHasTheFacts) {
  const Scene scene = small_scene();
  MeshDiagnostics d;
  d.border_edges = 3;
  d.components = 1;
  const json j = json::parse(inspect_report_json(scene, d));
  EXPECT_EQ(j["file"], "scene.gltf");
  EXPECT_EQ(j["triangles"], 1);
  EXPECT_EQ(j["vertices"], 3);
  EXPECT_EQ(j["nodes"], 2);
  EXPECT_EQ(j["draco_primitives"], 1);
  EXPECT_EQ(j["skipped_primitives"], 3);
  EXPECT_EQ(j["cameras"], 2);
  EXPECT_EQ(j["bounds"]["max"][1], 1.0);
  ASSERT_EQ(j["materials"].size(), 2u);
  const json& lamp = j["materials"][1];
  EXPECT_EQ(lamp["name"], "lamp");
  EXPECT_EQ(lamp["triangles"], 1);
  EXPECT_EQ(lamp["emissive"], true);
  EXPECT_FLOAT_EQ(lamp["emissive_radiance"][0].get<float>(), 10.f);
  EXPECT_FLOAT_EQ(lamp["emissive_radiance"][1].get<float>(), 5.f);
  EXPECT_EQ(lamp["emissive_radiance_unit"], "cd/m2");
  EXPECT_EQ(lamp["alpha_mode"], "MASK");
  EXPECT_FLOAT_EQ(lamp["alpha_cutoff"].get<float>(), 0.25f);
  EXPECT_EQ(lamp["double_sided"], true);
  EXPECT_EQ(lamp["textures"]["emissive"]["name"], "glow.png");
  EXPECT_EQ(lamp["textures"]["emissive"]["transform"]["scale"][0], 2.0);
  EXPECT_TRUE(lamp["textures"]["base_color"].is_null());
  EXPECT_EQ(j["materials"][0]["emissive"], false);
  EXPECT_EQ(j["textures"][0]["width"], 64);
  EXPECT_EQ(j["textures"][0]["height"], 32);
  ASSERT_EQ(j["lights"].size(), 2u);
  EXPECT_EQ(j["lights"][0]["type"], "directional");
  EXPECT_EQ(j["lights"][0]["unit"], "lux");
  EXPECT_FALSE(j["lights"][0].contains("position"));
  EXPECT_EQ(j["lights"][1]["type"], "spot");
  EXPECT_EQ(j["lights"][1]["unit"], "cd");
  EXPECT_EQ(j["lights"][1]["range"], 4.0);
  EXPECT_EQ(j["lights"][1]["position"][2], 3.0);
  EXPECT_TRUE(j["lights"][1].contains("outer_cone_angle"));
  EXPECT_EQ(j["diagnostics"]["border_edges"], 3);
  EXPECT_TRUE(j["diagnostics"]["self_intersecting_pairs"].is_null());
}

TEST(InspectReport, JsonSurvivesBadNamesAndNumbers) {
  Scene scene = small_scene();
  scene.materials[0].name = std::string("bad\xff\xfe utf8");
  scene.lights[0].intensity = std::numeric_limits<float>::infinity();
  scene.lights[1].intensity = std::nanf("");
  scene.bounds = Bounds{};
  const std::string text = inspect_report_json(scene, MeshDiagnostics{});
  const json j = json::parse(text);  // throws on invalid JSON
  EXPECT_TRUE(j["bounds"].is_null());
  EXPECT_TRUE(j["lights"][0]["intensity"].is_null());
  EXPECT_EQ(text.back(), '\n');
}

TEST(InspectReport, TextMentionsUnits) {
  MeshDiagnostics d;
  d.self_intersections_checked = true;
  d.self_intersecting_pairs = 7;
  const std::string text = inspect_report_text(small_scene(), d);
  EXPECT_NE(text.find("triangles: 1"), std::string::npos);
  EXPECT_NE(text.find("100000 lux"), std::string::npos);
  EXPECT_NE(text.find("50 cd"), std::string::npos);
  EXPECT_NE(text.find("cd/m2"), std::string::npos);
  EXPECT_NE(text.find("64x32"), std::string::npos);
  EXPECT_NE(text.find("self-intersecting triangle pairs: 7"), std::string::npos);
}

TEST(InspectReport, MissingFileIsAnError) {
  InspectResult r;
  const Status st = inspect_scene("/nonexistent/dir/scene.gltf", InspectOptions{}, Context{}, r);
  EXPECT_FALSE(st.is_ok());
  EXPECT_NE(st.message().find("scene.gltf"), std::string::npos);
}

}  // namespace
}  // namespace gibake
