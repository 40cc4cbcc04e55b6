// Import of generated glTF files: transforms, mirroring, modes, normals, quantization, sparse.
#include <cmath>

#include "tests/io/import_testutil.h"

namespace gibake::test {
namespace {

using V3 = std::array<double, 3>;

V3 pos(const Scene& s, uint32_t i) { return {s.positions[3 * i], s.positions[3 * i + 1], s.positions[3 * i + 2]}; }
V3 sub(V3 a, V3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 cross(V3 a, V3 b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
double dot(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Every triangle's CCW geometric normal points away from `centre`, and agrees with the vertex normals.
void expect_outward(const Scene& s, V3 centre) {
  ASSERT_GT(s.triangle_count(), 0u);
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    uint32_t a = s.indices[3 * t], b = s.indices[3 * t + 1], c = s.indices[3 * t + 2];
    V3 n = cross(sub(pos(s, b), pos(s, a)), sub(pos(s, c), pos(s, a)));
    V3 mid{(pos(s, a)[0] + pos(s, b)[0] + pos(s, c)[0]) / 3, (pos(s, a)[1] + pos(s, b)[1] + pos(s, c)[1]) / 3,
           (pos(s, a)[2] + pos(s, b)[2] + pos(s, c)[2]) / 3};
    EXPECT_GT(dot(n, sub(mid, centre)), 0.0) << "triangle " << t;
    V3 vn{s.normals[3 * a], s.normals[3 * a + 1], s.normals[3 * a + 2]};
    EXPECT_GT(dot(vn, sub(pos(s, a), centre)), 0.0) << "vertex normal of triangle " << t;
  }
}

std::string cube_file(const TempDir& dir, const json& node, const std::string& name, bool data_uri = true) {
  GltfBuilder g;
  int m = add_unit_cube_mesh(g);
  json n = node;
  n["mesh"] = m;
  g.node(n);
  return g.write(dir, name, data_uri);
}

TEST(ImportGenerated, MirroredNodeFlipsWinding) {
  TempDir dir;
  auto r = import_file(cube_file(dir, {{"scale", {-1, 1, 1}}, {"translation", {5, 0, 0}}}, "mirror"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 12u);
  ASSERT_EQ(r.scene.instances.size(), 1u);
  EXPECT_TRUE(r.scene.instances[0].mirrored);
  expect_outward(r.scene, {5, 0, 0});
}

TEST(ImportGenerated, MirrorByMatrixAndDoubleMirror) {
  TempDir dir;
  auto r = import_file(cube_file(dir, {{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -2, 0, 0, 3, 0, 1}}}, "m"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_TRUE(r.scene.instances[0].mirrored);
  expect_outward(r.scene, {0, 3, 0});
  EXPECT_NEAR(r.scene.bounds.min[2], -2.f, 1e-6);

  GltfBuilder g;
  int m = add_unit_cube_mesh(g);
  int child = g.node({{"mesh", m}, {"scale", {1, -1, 1}}}, false);
  g.node({{"children", {child}}, {"scale", {-1, 1, 1}}});
  auto r2 = import_file(g.write(dir, "double"));
  ASSERT_TRUE(r2.status.is_ok()) << r2.status.message();
  EXPECT_FALSE(r2.scene.instances[0].mirrored);
  expect_outward(r2.scene, {0, 0, 0});
}

TEST(ImportGenerated, PlainCubeWithExternalBuffer) {
  TempDir dir;
  auto r = import_file(cube_file(dir, json::object(), "plain", false));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_FALSE(r.scene.instances[0].mirrored);
  expect_outward(r.scene, {0, 0, 0});
  EXPECT_EQ(r.scene.input_files.size(), 2u);
}

// A 2x1 RGBA PNG (stored, zlib level 0): a red pixel, then a green one.
std::string two_pixel_png() {
  const unsigned char png[] = {
      0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
      0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0xf4, 0x22, 0x7f, 0x8a, 0x00, 0x00, 0x00,
      0x14, 0x49, 0x44, 0x41, 0x54, 0x78, 0x01, 0x01, 0x09, 0x00, 0xf6, 0xff, 0x00, 0xff, 0x00, 0x00, 0xff, 0x00,
      0xff, 0x00, 0xff, 0x10, 0xf8, 0x03, 0xfd, 0xd9, 0x64, 0xbc, 0x53, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e,
      0x44, 0xae, 0x42, 0x60, 0x82};
  return std::string(reinterpret_cast<const char*>(png), sizeof(png));
}

TEST(ImportGenerated, PercentEncodedUriAndTexturesWithoutDecoding) {
  TempDir dir;
  GltfBuilder g;
  int m = add_unit_cube_mesh(g, {{"material", 0}});
  g.node({{"mesh", m}});
  // The PNG in "tex dir/a b.png", referenced percent-encoded.
  write_file(dir.file("tex dir/a b.png"), two_pixel_png());
  g.doc["images"] = {{{"uri", "tex%20dir/a%20b.png"}}};
  g.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33648}}};
  g.doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  std::string path = g.write(dir, "tex");
  auto r = import_file(path);
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  ASSERT_EQ(r.scene.textures.size(), 1u);
  const Texture& t = r.scene.textures[0];
  EXPECT_EQ(t.width, 2);
  EXPECT_EQ(t.height, 1);
  ASSERT_EQ(t.rgba8.size(), 8u);
  EXPECT_EQ(t.rgba8[0], 255);  // red, then green
  EXPECT_EQ(t.rgba8[4], 0);
  EXPECT_EQ(t.rgba8[5], 255);
  EXPECT_EQ(t.wrap_s, 33071);
  EXPECT_EQ(t.wrap_t, 33648);
  EXPECT_EQ(r.scene.materials[0].base_color_texture.texture, 0);
  EXPECT_EQ(r.scene.tri_material[0], 0);
  EXPECT_EQ(r.scene.input_files.size(), 2u);  // the .gltf (data: buffer) and the PNG

  ImportOptions no_pixels;
  no_pixels.load_textures = false;
  auto h = import_file(path, no_pixels);
  ASSERT_TRUE(h.status.is_ok()) << h.status.message();
  EXPECT_EQ(h.scene.textures[0].width, 2);
  EXPECT_TRUE(h.scene.textures[0].rgba8.empty());
}

// A valid IHDR passes the header checks; the broken zlib stream inside IDAT only shows when the
// pixels are decoded (after parsing, in parallel), and must still end as a warning in image order.
TEST(ImportGenerated, CorruptPngDataIsSkippedWithAWarning) {
  TempDir dir;
  GltfBuilder g;
  int m = add_unit_cube_mesh(g, {{"material", 0}});
  g.node({{"mesh", m}});
  std::string bad = two_pixel_png();
  ASSERT_EQ(uint8_t(bad[41]), 0x78);  // the zlib header, first byte of IDAT's data
  bad[41] = char(0x79);               // (CMF * 256 + FLG) % 31 != 0: stb refuses the stream
  write_file(dir.file("bad.png"), bad);
  write_file(dir.file("good.png"), two_pixel_png());
  g.doc["images"] = {
      {{"uri", "bad.png"}}, {{"uri", "good.png"}}, {{"uri", "data:image/png;base64," + base64(bad)}}};
  g.doc["textures"] = {{{"source", 0}}, {{"source", 1}}, {{"source", 2}}};
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}},
                        {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}},
                        {{"emissiveTexture", {{"index", 2}}}}};
  std::string path = g.write(dir, "corrupt");
  for (unsigned threads : {1u, 0u}) {
    auto r = import_file(path, {}, threads);
    ASSERT_TRUE(r.status.is_ok()) << r.status.message();
    EXPECT_EQ(r.warnings,
              (std::vector<std::string>{path + ": images[0] ('bad.png'): image could not be decoded; image ignored",
                                        path + ": images[2]: image could not be decoded; image ignored"}));
    ASSERT_EQ(r.scene.textures.size(), 3u);
    for (size_t t : {size_t(0), size_t(2)}) {
      EXPECT_EQ(r.scene.textures[t].width, 0) << t;
      EXPECT_EQ(r.scene.textures[t].height, 0) << t;
      EXPECT_TRUE(r.scene.textures[t].rgba8.empty()) << t;
    }
    EXPECT_EQ(r.scene.textures[1].width, 2);
    EXPECT_EQ(r.scene.textures[1].rgba8, (std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 255}));
  }
}

// Images no material uses for base colour or emission (normal maps, say) are header-checked but
// not decoded: they keep their size and have no pixels, and a corrupt one raises no warning.
TEST(ImportGenerated, ImagesNoMaterialUsesAreNotDecoded) {
  TempDir dir;
  GltfBuilder g;
  int m = add_unit_cube_mesh(g, {{"material", 0}});
  g.node({{"mesh", m}});
  std::string bad = two_pixel_png();
  bad[41] = char(0x79);  // broken zlib stream: only a decode would notice
  write_file(dir.file("bad.png"), bad);
  write_file(dir.file("good.png"), two_pixel_png());
  g.doc["images"] = {{{"uri", "good.png"}}, {{"uri", "bad.png"}}, {{"uri", "good.png"}}};
  g.doc["textures"] = {{{"source", 0}}, {{"source", 1}}, {{"source", 2}}};
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
                         {"normalTexture", {{"index", 1}}},
                         {"occlusionTexture", {{"index", 2}}}}};
  auto r = import_file(g.write(dir, "unused"), {});
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_TRUE(r.warnings.empty());
  ASSERT_EQ(r.scene.textures.size(), 3u);
  EXPECT_EQ(r.scene.textures[0].rgba8.size(), 8u);
  for (size_t t : {size_t(1), size_t(2)}) {
    EXPECT_EQ(r.scene.textures[t].width, 2) << t;
    EXPECT_TRUE(r.scene.textures[t].rgba8.empty()) << t;
  }
}

TEST(ImportGenerated, StripAndFanAreTriangulatedWithFlatNormals) {
  TempDir dir;
  GltfBuilder g;
  // A quad in z=0 as a strip (0,1,2,3) and as a fan (0,1,3,2), non-indexed.
  std::vector<float> strip = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  std::vector<float> fan = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  g.mesh({{"attributes", {{"POSITION", g.floats(strip, "VEC3", 3)}}}, {"mode", 5}});
  g.mesh({{"attributes", {{"POSITION", g.floats(fan, "VEC3", 3)}}}, {"mode", 6}});
  g.mesh({{"attributes", {{"POSITION", g.floats(fan, "VEC3", 3)}}}, {"mode", 1}});
  g.node({{"mesh", 0}});
  g.node({{"mesh", 1}});
  g.node({{"mesh", 2}});
  auto r = import_file(g.write(dir, "modes"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 4u);
  EXPECT_EQ(r.scene.stats.skipped_primitives, 1u);
  EXPECT_FALSE(r.warnings.empty());
  for (size_t t = 0; t < 4; ++t) {
    uint32_t a = r.scene.indices[3 * t], b = r.scene.indices[3 * t + 1], c = r.scene.indices[3 * t + 2];
    V3 n = cross(sub(pos(r.scene, b), pos(r.scene, a)), sub(pos(r.scene, c), pos(r.scene, a)));
    EXPECT_GT(n[2], 0.0) << t;  // all CCW seen from +Z
    EXPECT_NEAR(r.scene.normals[3 * a + 2], 1.f, 1e-6);
  }
}

TEST(ImportGenerated, QuantizedPositionsColorsAndSparse) {
  TempDir dir;
  GltfBuilder g;
  // KHR_mesh_quantization: normalized short positions, ubyte normalized RGB colours.
  std::vector<int16_t> p = {0, 0, 0, 0, 32767, 0, 0, 0, 0, 32767, 0, 0};  // stride 8 (padded vec3)
  int pv = g.view(p, 8);
  int pa = g.accessor(pv, 5122, 3, "VEC3", true);
  std::vector<uint8_t> col = {255, 0, 0, 0, 0, 255, 0, 0, 0, 0, 255, 0};
  int ca = g.accessor(g.view(col, 4), 5121, 3, "VEC3", true);
  // Sparse: replace vertex 2's position by (0, 2, 0) through a float sparse accessor on a zero base.
  std::vector<float> base = {0, 0, 0, 2, 0, 0, 0, 0, 0};
  int sa = g.floats(base, "VEC3", 3);
  std::vector<uint8_t> sidx = {2, 0, 0, 0};
  std::vector<float> sval = {0, 2, 0};
  int iv = g.view(sidx), vv = g.view(sval);
  g.doc["accessors"][size_t(sa)]["sparse"] = {{"count", 1},
                                              {"indices", {{"bufferView", iv}, {"componentType", 5121}}},
                                              {"values", {{"bufferView", vv}}}};
  g.mesh({{"attributes", {{"POSITION", pa}, {"COLOR_0", ca}}}});
  g.mesh({{"attributes", {{"POSITION", sa}}}});
  g.node({{"mesh", 0}});
  g.node({{"mesh", 1}});
  g.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  g.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  auto r = import_file(g.write(dir, "quant"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  const Scene& s = r.scene;
  ASSERT_EQ(s.triangle_count(), 2u);
  EXPECT_NEAR(s.positions[3], 1.f, 1e-6);  // 32767/32767
  EXPECT_NEAR(s.positions[7], 1.f, 1e-6);
  ASSERT_EQ(s.colors.size(), s.vertex_count() * 4);
  EXPECT_FLOAT_EQ(s.colors[0], 1.f);
  EXPECT_FLOAT_EQ(s.colors[3], 1.f);   // alpha filled
  EXPECT_FLOAT_EQ(s.colors[5], 1.f);   // vertex 1 green
  EXPECT_FLOAT_EQ(s.colors[12], 1.f);  // second primitive: white
  EXPECT_FLOAT_EQ(s.positions[9 + 6 + 1], 2.f);  // sparse-substituted vertex 2 y
  EXPECT_EQ(s.tri_material[0], -1);
}

TEST(ImportGenerated, NoScenesUsesRootNodes) {
  TempDir dir;
  GltfBuilder g;
  int m = add_unit_cube_mesh(g);
  g.node({{"mesh", m}});
  g.doc.erase("scenes");
  g.doc.erase("scene");
  auto r = import_file(g.write(dir, "noscene"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.triangle_count(), 12u);
}

TEST(ImportGenerated, SpotLightDirectionFollowsNode) {
  TempDir dir;
  GltfBuilder g;
  int m = add_unit_cube_mesh(g);
  g.node({{"mesh", m}});
  // Rotate -90 degrees about X: local -Z becomes world -Y.
  double s = std::sqrt(0.5);
  g.node({{"translation", {0, 4, 0}}, {"rotation", {-s, 0, 0, s}},
          {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  g.doc["extensions"] = {{"KHR_lights_punctual",
                          {{"lights", {{{"type", "spot"}, {"intensity", 30}, {"range", 10},
                                        {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}}}}}}};
  auto r = import_file(g.write(dir, "spot"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  ASSERT_EQ(r.scene.lights.size(), 1u);
  const Light& l = r.scene.lights[0];
  EXPECT_EQ(l.type, Light::Type::Spot);
  EXPECT_NEAR(l.direction[1], -1.f, 1e-6);
  EXPECT_NEAR(l.position[1], 4.f, 1e-6);
  EXPECT_FLOAT_EQ(l.outer_cone_angle, 0.5f);
  EXPECT_FLOAT_EQ(l.range, 10.f);
}

// glTF requires flat normals where a primitive gives none, whether or not its vertices are
// shared through indices: every vertex normal of the indexed cube is its triangle's.
TEST(ImportGenerated, IndexedMeshWithoutNormalsGetsFlatNormals) {
  TempDir dir;
  auto r = import_file(cube_file(dir, json::object(), "flat"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  const Scene& s = r.scene;
  ASSERT_EQ(s.triangle_count(), 12u);
  for (size_t t = 0; t < s.triangle_count(); ++t) {
    const uint32_t a = s.indices[3 * t], b = s.indices[3 * t + 1], c = s.indices[3 * t + 2];
    V3 n = cross(sub(pos(s, b), pos(s, a)), sub(pos(s, c), pos(s, a)));
    const double l = std::sqrt(dot(n, n));
    for (uint32_t v : {a, b, c})
      for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(s.normals[3 * v + k], n[k] / l, 1e-6) << "triangle " << t;
  }
}

// A quad with one morph target that lifts it 2 m: the mesh's default weights place it, a node's
// weights override them, and two nodes of the same mesh at other weights each get their own shape.
TEST(ImportGenerated, MorphTargetsAtTheirDefaultWeights) {
  TempDir dir;
  GltfBuilder g;
  const std::vector<float> quad = {0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0};
  const std::vector<float> lift = {0, 2, 0, 0, 2, 0, 0, 2, 0, 0, 2, 0};
  const std::vector<uint16_t> idx = {0, 1, 2, 0, 2, 3};
  const int lifted = g.floats(lift, "VEC3", 3);
  g.mesh({{"attributes", {{"POSITION", g.floats(quad, "VEC3", 3)}}},
          {"indices", g.indices(idx)},
          {"targets", json::array({{{"POSITION", lifted}}})}});
  g.doc["meshes"][0]["weights"] = {1.0};
  g.node({{"mesh", 0}});
  g.node({{"mesh", 0}, {"weights", {0.25}}, {"translation", {5, 0, 0}}});
  auto r = import_file(g.write(dir, "morph"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  const Scene& s = r.scene;
  ASSERT_EQ(s.instances.size(), 2u);
  for (size_t v = 0; v < s.vertex_count(); ++v)
    EXPECT_FLOAT_EQ(s.positions[3 * v + 1], s.positions[3 * v] < 2.f ? 2.f : 0.5f) << "vertex " << v;
  EXPECT_TRUE(r.warnings.empty());
}

// A skinned quad is posed by its joint, not placed by its own node: the joint 1 m up (no inverse
// bind matrices: identity) lifts it 1 m, and the mesh node's translation of 5 m is ignored (glTF
// 3.7.3). A second skin's joint mirrors y (scale -1) 3 m up: the quad turns over, and its
// triangles keep their front on the mirrored side (geometric and vertex normals -y).
TEST(ImportGenerated, SkinsPoseTheirMeshesByTheirJoints) {
  TempDir dir;
  GltfBuilder g;
  const std::vector<float> quad = {0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0};  // front +y
  const std::vector<uint16_t> idx = {0, 1, 2, 0, 2, 3};
  const std::vector<uint8_t> joints(16, 0);
  const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  const int ja = g.accessor(g.view(joints), 5121, 4, "VEC4");
  const int wa = g.floats(weights, "VEC4", 4);
  g.mesh({{"attributes", {{"POSITION", g.floats(quad, "VEC3", 3)}, {"JOINTS_0", ja}, {"WEIGHTS_0", wa}}},
          {"indices", g.indices(idx)}});
  const int up = g.node({{"translation", {0, 1, 0}}});
  g.node({{"mesh", 0}, {"skin", 0}, {"translation", {5, 0, 0}}});
  const int mirror = g.node({{"translation", {0, 3, 0}}, {"scale", {1, -1, 1}}});
  g.node({{"mesh", 0}, {"skin", 1}});
  g.doc["skins"] = json::array({{{"joints", {up}}}, {{"joints", {mirror}}}});
  auto r = import_file(g.write(dir, "skin"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  const Scene& s = r.scene;
  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_FLOAT_EQ(s.bounds.min[0], 0.f);
  EXPECT_FLOAT_EQ(s.bounds.max[0], 1.f);
  const double height[2] = {1.0, 3.0}, front[2] = {1.0, -1.0};
  for (size_t i = 0; i < 2; ++i) {
    const PrimitiveInstance& inst = s.instances[i];
    for (uint32_t t = inst.first_triangle; t < inst.first_triangle + inst.triangle_count; ++t) {
      const uint32_t a = s.indices[3 * t], b = s.indices[3 * t + 1], c = s.indices[3 * t + 2];
      for (uint32_t v : {a, b, c}) EXPECT_NEAR(s.positions[3 * v + 1], height[i], 1e-6);
      const V3 n = cross(sub(pos(s, b), pos(s, a)), sub(pos(s, c), pos(s, a)));
      EXPECT_GT(n[1] * front[i], 0.0) << "skin " << i << ", triangle " << t;
      EXPECT_GT(s.normals[3 * a + 1] * front[i], 0.9) << "skin " << i << ", triangle " << t;
    }
  }
}

}  // namespace
}  // namespace gibake::test
