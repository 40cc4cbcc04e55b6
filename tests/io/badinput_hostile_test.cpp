// Hostile inputs generated at run time: each must end in a clean InvalidInput (or IoFailure)
// that names the place, never a crash, hang or huge allocation.
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include "tests/io/import_testutil.h"

namespace gibake::test {
namespace {

void expect_refused(const ImportResult& r, ExitCode code, const std::string& where, const std::string& what) {
  ASSERT_FALSE(r.status.is_ok());
  EXPECT_EQ(r.status.code(), code) << r.status.message();
  EXPECT_NE(r.status.where().find(where), std::string::npos) << "where: " << r.status.message();
  EXPECT_NE(r.status.what().find(what), std::string::npos) << "what: " << r.status.message();
  EXPECT_TRUE(r.scene.positions.empty());
}

void expect_invalid(const std::string& path, const std::string& where, const std::string& what,
                    ImportOptions opt = {}) {
  SCOPED_TRACE(path);
  expect_refused(import_file(path, opt), ExitCode::InvalidInput, where, what);
}

// A valid cube document; tests break one thing in it.
GltfBuilder cube() {
  GltfBuilder g;
  int m = add_unit_cube_mesh(g);
  g.node({{"mesh", m}});
  return g;
}

uint32_t crc32(const std::string& s) {
  uint32_t c = 0xFFFFFFFFu;
  for (unsigned char ch : s) {
    c ^= ch;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

// A PNG whose IHDR claims w x h; there is no image data to decode.
std::string png_header(uint32_t w, uint32_t h) {
  auto be = [](uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  };
  std::string ihdr = "IHDR" + be(w) + be(h) + std::string{8, 6, 0, 0, 0};
  std::string iend = "IEND";
  return std::string("\x89PNG\r\n\x1a\n", 8) + be(13) + ihdr + be(crc32(ihdr)) + be(0) + iend + be(crc32(iend));
}

std::string with_buffer_uri(const TempDir& dir, const std::string& uri) {
  GltfBuilder g = cube();
  std::string path = g.write(dir, "scene", false);
  json d = json::parse(read_file(path));
  d["buffers"][0]["uri"] = uri;
  write_file(path, d.dump());
  return path;
}

TEST(BadInputHostile, UriEscapesAndSchemesAreRefused) {
  TempDir dir;
  write_file(dir.file("secret.bin"), std::string(400, 'x'));
  fs::create_directories(dir.path / "sub");
  struct Case { std::string uri, what; };
  for (const Case& c : {Case{"../secret.bin", "escapes"}, Case{"%2e%2e/secret.bin", "escapes"},
                        Case{"a/../../secret.bin", "escapes"}, Case{dir.file("secret.bin"), "absolute"},
                        Case{"/etc/passwd", "absolute"}, Case{"file:///etc/passwd", "scheme"},
                        Case{"http://example.com/scene.bin", "scheme"}, Case{"C:/scene.bin", "drive letter"},
                        Case{"\\\\server\\share\\scene.bin", "backslash"}, Case{"..\\secret.bin", "backslash"},
                        Case{"data:application/x-evil,AAAA", "data:"}}) {
    TempDir sub;
    SCOPED_TRACE(c.uri);
    expect_invalid(with_buffer_uri(sub, c.uri), "buffers[0].uri", c.what);
  }
}

TEST(BadInputHostile, SymlinkOutOfTheFolderIsRefused) {
  TempDir outside, dir;
  GltfBuilder g = cube();
  g.write(outside, "real", false);  // real.bin lives outside `dir`
  fs::create_symlink(outside.file("real.bin"), dir.path / "link.bin");
  expect_invalid(with_buffer_uri(dir, "link.bin"), "buffers[0].uri", "outside the scene folder");
}

TEST(BadInputHostile, SizeAndPixelCaps) {
  TempDir dir;
  ImportOptions small;
  small.limits.max_file_bytes = 100;
  expect_invalid(cube().write(dir, "big"), "", "over the limit", small);
  // 64x64 PNG claim against a 32-pixel side limit, and against a 1000-pixel total.
  GltfBuilder g = cube();
  write_file(dir.file("p.png"), png_header(64, 64));
  g.doc["images"] = {{{"uri", "p.png"}}};
  ImportOptions side;
  side.limits.max_image_dimension = 32;
  expect_invalid(g.write(dir, "side"), "images[0]", "per side", side);
  ImportOptions px;
  px.limits.max_image_pixels = 1000;
  expect_invalid(g.write(dir, "px"), "images[0]", "pixels", px);
}

// The total-pixel budget counts each accepted header, in image order, before anything is decoded
// (these PNGs have no pixel data at all), so the refusal names the first image over the total.
TEST(BadInputHostile, TotalPixelBudgetCountsHeadersInImageOrder) {
  TempDir dir;
  GltfBuilder g = cube();
  write_file(dir.file("p.png"), png_header(64, 64));
  g.doc["images"] = {{{"uri", "p.png"}}, {{"uri", "p.png"}}, {{"uri", "p.png"}}};
  std::string path = g.write(dir, "total");
  ImportOptions opt;
  opt.limits.max_total_pixels = 2 * 64 * 64;
  expect_invalid(path, "images[2]", "all images together exceed the pixel limit", opt);
  opt.load_textures = false;  // headers only: no budget to exceed
  auto r = import_file(path, opt);
  EXPECT_TRUE(r.status.is_ok()) << r.status.message();
}

// Image files are read side by side after parsing, but as if one by one in image order: a missing
// file is skipped with a warning, the byte budget runs out at the same image, and the input list
// keeps image order, whatever the thread count.
TEST(BadInputHostile, ImageFilesFollowImageOrderWhenReadInParallel) {
  TempDir dir;
  GltfBuilder g = cube();
  const std::string png = png_header(8, 8);
  for (const char* name : {"p1.png", "p2.png", "p3.png"}) write_file(dir.file(name), png);
  g.doc["images"] = {{{"uri", "p1.png"}}, {{"uri", "gone.png"}}, {{"uri", "p2.png"}}, {{"uri", "p3.png"}}};
  const std::string path = g.write(dir, "files");
  for (unsigned threads : {1u, 0u}) {
    SCOPED_TRACE(threads);
    ImportOptions tight;
    tight.limits.max_total_buffer_bytes = 2 * png.size() + png.size() / 2;  // p3.png does not fit
    auto refused = import_file(path, tight, threads);
    expect_refused(refused, ExitCode::InvalidInput, "", "over the limit");
    EXPECT_NE(refused.status.file().find("p3.png"), std::string::npos) << refused.status.message();
    ImportOptions enough;
    enough.limits.max_total_buffer_bytes = 3 * png.size();
    auto r = import_file(path, enough, threads);
    ASSERT_TRUE(r.status.is_ok()) << r.status.message();
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("images[1]: image file 'gone.png' not found; image ignored"), std::string::npos)
        << r.warnings[0];
    ASSERT_EQ(r.scene.input_files.size(), 4u);  // the .gltf, then the images in order
    for (size_t k = 0; k < 3; ++k)
      EXPECT_NE(r.scene.input_files[k + 1].find("p" + std::to_string(k + 1) + ".png"), std::string::npos);
    ASSERT_EQ(r.scene.textures.size(), 0u);  // no texture references them; the headers were still checked
  }
}

TEST(BadInputHostile, ImageUriEscapeIsRefused) {
  TempDir dir;
  GltfBuilder g = cube();
  g.doc["images"] = {{{"uri", "../../../etc/passwd"}}};
  g.doc["textures"] = {{{"source", 0}}};
  expect_invalid(g.write(dir, "img"), "images[0].uri", "escapes");
}

TEST(BadInputHostile, MissingFilesAreIoFailures) {
  TempDir dir;
  expect_refused(import_file(dir.file("nothing.gltf")), ExitCode::IoFailure, "", "cannot open");
  auto r = import_file(with_buffer_uri(dir, "missing.bin"));
  expect_refused(r, ExitCode::IoFailure, "", "buffers[0]");
  EXPECT_NE(r.status.file().find("missing.bin"), std::string::npos);
}

TEST(BadInputHostile, GarbageAndEmptyFiles) {
  TempDir dir;
  write_file(dir.file("empty.gltf"), "");
  write_file(dir.file("garbage.gltf"), "{\"asset\": [");
  write_file(dir.file("short.glb"), "glTF\x02");
  expect_invalid(dir.file("garbage.gltf"), "JSON", "JSON");
  for (const char* f : {"empty.gltf", "short.glb"}) {
    auto r = import_file(dir.file(f));
    EXPECT_EQ(r.status.code(), ExitCode::InvalidInput) << r.status.message();
  }
}

TEST(BadInputHostile, JsonErrorsNameTheirPlace) {
  TempDir dir;
  write_file(dir.file("cut.gltf"), "{\"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [");
  expect_invalid(dir.file("cut.gltf"), "JSON", "not valid JSON at line 2, column");
  write_file(dir.file("huge.gltf"), "{\"asset\": {\"version\": \"2.0\"}, \"extras\": 1e400}");
  expect_invalid(dir.file("huge.gltf"), "JSON", "number overflow parsing '1e400'");
}

TEST(BadInputHostile, DataUrisAreCheckedWhereTheyStand) {
  TempDir a, b, c;
  expect_invalid(with_buffer_uri(a, "data:application/octet-stream;base64,AAAA$$$!!"), "buffers[0].uri",
                 "not valid base64 (character 4 of its data)");
  // Valid base64 holding fewer bytes than the cube's buffer says.
  expect_invalid(with_buffer_uri(b, "data:application/octet-stream;base64,AAAAAAAA"), "buffers[0].uri",
                 "data: URI holds 6 bytes, fewer than the buffer's byteLength");
  // The scene's own folder is no file, and does not escape it either.
  expect_invalid(with_buffer_uri(c, "."), "buffers[0].uri", "names the scene folder itself");
}

// Values the glTF parser would refuse without naming the accessor or view are named here.
TEST(BadInputHostile, AccessorAndViewValuesNameTheirPlace) {
  struct Case {
    const char* array;
    const char* key;
    json value;
    const char* what;
  };
  for (const Case& c : {Case{"accessors", "componentType", 9999, "9999 is not a glTF component type"},
                        Case{"accessors", "type", "VEC5", "\"VEC5\" is not a glTF accessor type"},
                        Case{"bufferViews", "byteStride", 4294967292.0, "is not a glTF byte stride"},
                        Case{"bufferViews", "byteStride", 6, "6 is not a glTF byte stride"}}) {
    SCOPED_TRACE(std::string(c.key) + " " + c.value.dump());
    TempDir dir;
    GltfBuilder g = cube();
    const std::string path = g.write(dir, "scene", false);
    json d = json::parse(read_file(path));
    d[c.array][0][c.key] = c.value;
    write_file(path, d.dump());
    expect_invalid(path, std::string(c.array) + "[0]." + c.key, c.what);
  }
}

TEST(BadInputHostile, PlacesBeyondTheTracersRangeAreRefused) {
  TempDir dir;
  GltfBuilder g;
  int m = add_unit_cube_mesh(g);
  g.node({{"mesh", m}, {"translation", {1e19, 0.0, 0.0}}});
  expect_invalid(g.write(dir, "far"), "nodes[0]", "lies beyond 1e+16 m of the origin");
  // Far but within range: imported.
  TempDir near_dir;
  GltfBuilder h;
  int hm = add_unit_cube_mesh(h);
  h.node({{"mesh", hm}, {"translation", {1e15, 0.0, 0.0}}});
  EXPECT_TRUE(import_file(h.write(near_dir, "far_enough")).status.is_ok());
}

TEST(BadInputHostile, MaterialFactorsBeyondAFloatAreReported) {
  TempDir dir;
  GltfBuilder g = cube();
  std::string path = g.write(dir, "scene", false);
  json d = json::parse(read_file(path));
  d["materials"] = json::array({{{"emissiveFactor", {1e39, 1.0, 1.0}}}});
  d["meshes"][0]["primitives"][0]["material"] = 0;
  write_file(path, d.dump());
  const ImportResult r = import_file(path);
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.materials.at(0).emissive[0], 0.f);
  bool said = false;
  for (const std::string& w : r.warnings)
    said = said || w.find("materials[0].emissiveFactor[0]: 1e+39 is not a finite float; 0 used") != std::string::npos;
  EXPECT_TRUE(said);
}

// glTF bounds baseColorFactor to 0..1; an albedo above 1 makes the paths' light grow without bound
// (and overflow). Values outside are clamped into it, and said so.
TEST(BadInputHostile, BaseColourOutsideZeroToOneIsClampedAndReported) {
  TempDir dir;
  GltfBuilder g = cube();
  std::string path = g.write(dir, "scene", false);
  json d = json::parse(read_file(path));
  d["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {5.0, 0.5, -1.0, 1.0}}}}}});
  d["meshes"][0]["primitives"][0]["material"] = 0;
  write_file(path, d.dump());
  const ImportResult r = import_file(path);
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  EXPECT_EQ(r.scene.materials.at(0).base_color[0], 1.f);
  EXPECT_EQ(r.scene.materials.at(0).base_color[1], 0.5f);
  EXPECT_EQ(r.scene.materials.at(0).base_color[2], 0.f);
  int said = 0;
  for (const std::string& w : r.warnings)
    said +=
        w.find("materials[0].pbrMetallicRoughness.baseColorFactor[0]: 5 is outside 0..1; 1 used") !=
            std::string::npos ||
        w.find("materials[0].pbrMetallicRoughness.baseColorFactor[2]: -1 is outside 0..1; 0 used") != std::string::npos;
  EXPECT_EQ(said, 2);
}

// An image URI naming a folder is said to be one, not to be missing.
TEST(BadInputHostile, ImageUriOfAFolderIsNamedSo) {
  TempDir dir;
  GltfBuilder g = cube();
  std::filesystem::create_directories(dir.file("sub"));
  g.doc["images"] = {{{"uri", "sub"}}};
  const ImportResult r = import_file(g.write(dir, "folder"));
  ASSERT_TRUE(r.status.is_ok()) << r.status.message();
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("images[0]: image file 'sub' is not a regular file; image ignored"), std::string::npos)
      << r.warnings[0];
}

TEST(BadInputHostile, DeepJsonNestingIsRefused) {
  TempDir dir;
  GltfBuilder g = cube();
  std::string path = g.write(dir, "deep");
  std::string text = read_file(path);
  text.insert(text.size() - 1, ",\"extras\":" + std::string(200000, '[') + std::string(200000, ']'));
  write_file(path, text);
  expect_invalid(path, "JSON", "nesting");
}

TEST(BadInputHostile, ViewlessAccessorCountIsCapped) {
  TempDir dir;
  GltfBuilder g = cube();
  g.doc["accessors"][0].erase("bufferView");
  g.doc["accessors"][0]["count"] = uint64_t(1) << 40;
  expect_invalid(g.write(dir, "zeros"), "accessors[0]", "count too large");
}

TEST(BadInputHostile, GlbChunkLengthLies) {
  TempDir dir;
  GltfBuilder g = cube();
  std::string gltf = read_file(g.write(dir, "c"));
  json d = json::parse(gltf);
  d["buffers"] = json::array({{{"byteLength", g.bin.size()}}});
  std::string js = d.dump();
  while (js.size() % 4) js += ' ';
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  std::string bin_chunk = u32(uint32_t(g.bin.size()) + 64) + "BIN" + std::string(1, '\0') + g.bin;
  std::string glb = "glTF" + u32(2) + u32(uint32_t(20 + js.size() + bin_chunk.size())) + u32(uint32_t(js.size())) +
                    "JSON" + js + bin_chunk;
  write_file(dir.file("lie.glb"), glb);
  expect_invalid(dir.file("lie.glb"), "GLB BIN chunk", "past the end");
}

TEST(BadInputHostile, AccessorRangesAreOverflowChecked) {
  TempDir dir;
  {
    GltfBuilder g = cube();
    g.doc["accessors"][0]["count"] = uint64_t(1) << 62;
    expect_invalid(g.write(dir, "count"), "accessors[0]", "exceeds");
  }
  {
    GltfBuilder g = cube();
    g.doc["accessors"][0]["byteOffset"] = std::numeric_limits<uint64_t>::max() - 3;
    expect_invalid(g.write(dir, "offset"), "accessors[0]", "");
  }
  {
    GltfBuilder g = cube();
    g.doc["bufferViews"][0]["byteLength"] = 1u << 30;
    expect_invalid(g.write(dir, "view"), "bufferViews[0]", "exceeds the buffer");
  }
  {
    GltfBuilder g = cube();
    g.doc["accessors"][0]["componentType"] = 5130;
    expect_invalid(g.write(dir, "ctype"), "accessors[0].componentType", "is not a glTF component type");
  }
  {
    GltfBuilder g = cube();
    g.doc["accessors"][0]["bufferView"] = 42;
    auto r = import_file(g.write(dir, "viewidx"));
    EXPECT_EQ(r.status.code(), ExitCode::InvalidInput) << r.status.message();
  }
}

TEST(BadInputHostile, IndexOutOfRange) {
  TempDir dir;
  GltfBuilder g;
  std::vector<float> p = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<uint16_t> i = {0, 1, 7};
  g.mesh({{"attributes", {{"POSITION", g.floats(p, "VEC3", 3)}}}, {"indices", g.indices(i)}});
  g.node({{"mesh", 0}});
  expect_invalid(g.write(dir, "idx"), "meshes[0].primitives[0]", "index 7");
}

TEST(BadInputHostile, SparseIndexOutOfRange) {
  TempDir dir;
  GltfBuilder g = cube();
  std::vector<uint8_t> sidx = {200, 0, 0, 0};
  std::vector<float> sval = {0, 2, 0};
  int iv = g.view(sidx), vv = g.view(sval);
  g.doc["accessors"][0]["sparse"] = {{"count", 1},
                                     {"indices", {{"bufferView", iv}, {"componentType", 5121}}},
                                     {"values", {{"bufferView", vv}}}};
  expect_invalid(g.write(dir, "sparse"), "accessors[0].sparse", "sparse index 200");
}

TEST(BadInputHostile, NanPosition) {
  TempDir dir;
  GltfBuilder g;
  std::vector<float> p = {0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 0};
  g.mesh({{"attributes", {{"POSITION", g.floats(p, "VEC3", 3)}}}});
  g.node({{"mesh", 0}});
  expect_invalid(g.write(dir, "nan"), "meshes[0].primitives[0]", "NaN");
}

TEST(BadInputHostile, NodeCyclesAndTwoParents) {
  TempDir dir;
  {
    GltfBuilder g = cube();
    g.doc["nodes"][0]["children"] = {1};
    g.doc["nodes"].push_back({{"children", {0}}});
    expect_invalid(g.write(dir, "cycle"), "", "");  // root with a parent, or a cycle
  }
  {
    GltfBuilder g = cube();
    g.doc["nodes"].push_back({{"children", {2}}});
    g.doc["nodes"].push_back({{"children", {1}}});
    expect_invalid(g.write(dir, "cycle2"), "nodes[", "cycle");
  }
  {
    GltfBuilder g = cube();
    g.doc["nodes"][0]["children"] = {0};
    expect_invalid(g.write(dir, "self"), "nodes[0]", "cycle");
  }
  {
    GltfBuilder g = cube();
    g.doc["nodes"].push_back({{"children", {0}}});
    g.doc["nodes"].push_back({{"children", {0}}});
    g.doc["scenes"][0]["nodes"] = {1, 2};
    expect_invalid(g.write(dir, "parents"), "nodes[0]", "two parents");
  }
}

TEST(BadInputHostile, NoTriangles) {
  TempDir dir;
  GltfBuilder g;
  std::vector<float> p = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.mesh({{"attributes", {{"POSITION", g.floats(p, "VEC3", 3)}}}, {"mode", 0}});
  g.node({{"mesh", 0}});
  expect_invalid(g.write(dir, "points"), "scene", "scene has no triangles");
  GltfBuilder e;
  expect_invalid(e.write(dir, "empty"), "scene", "scene has no triangles");
}

TEST(BadInputHostile, TriangleCapAndUnsupportedRequiredExtension) {
  TempDir dir;
  ImportOptions opt;
  opt.limits.max_triangles = 5;
  expect_invalid(cube().write(dir, "cap"), "nodes[0]", "triangle limit", opt);
  GltfBuilder g = cube();
  g.doc["extensionsRequired"] = {"EXT_meshopt_compression"};
  expect_invalid(g.write(dir, "ext"), "extensionsRequired[0]", "EXT_meshopt_compression");
}

TEST(BadInputHostile, HugePngDimensionsRefusedBeforeDecoding) {
  TempDir dir;
  write_file(dir.file("huge.png"), png_header(65535, 65535));
  GltfBuilder g = cube();
  g.doc["images"] = {{{"uri", "huge.png"}}};
  g.doc["textures"] = {{{"source", 0}}};
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  auto r = import_file(g.write(dir, "png"));
  expect_refused(r, ExitCode::InvalidInput, "images[0]", "65535x65535");
  EXPECT_NE(r.status.file().find("huge.png"), std::string::npos);

  GltfBuilder e = cube();
  e.doc["images"] = {{{"uri", "data:image/png;base64," + base64(png_header(65535, 65535))}}};
  expect_invalid(e.write(dir, "png_data"), "images[0]", "over the limit");

  GltfBuilder v = cube();  // an image in a bufferView that runs past its buffer
  v.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 4}, {"byteLength", 100000}});
  v.doc["images"] = {{{"bufferView", 2}, {"mimeType", "image/png"}}};
  auto rv = import_file(v.write(dir, "png_view"));
  EXPECT_EQ(rv.status.code(), ExitCode::InvalidInput) << rv.status.message();
}

// The shared Draco box copied into `dir` with its document edited by `edit` and the stream cut.
std::string draco_box(const TempDir& dir, size_t keep_bytes, const std::function<void(json&)>& edit) {
  std::string bin = read_file(asset("draco/box/Box.bin"));
  json d = json::parse(read_file(asset("draco/box/Box.gltf")));
  if (keep_bytes < bin.size()) {
    bin.resize(keep_bytes);
    d["buffers"][0]["byteLength"] = keep_bytes;
    d["bufferViews"][0]["byteLength"] = keep_bytes;
  }
  edit(d);
  write_file(dir.file("Box.bin"), bin);
  write_file(dir.file("Box.gltf"), d.dump());
  return dir.file("Box.gltf");
}

TEST(BadInputHostile, DracoTruncatedAndLyingStreams) {
  const std::string w = "meshes[0].primitives[0].KHR_draco_mesh_compression";
  auto nothing = [](json&) {};
  for (size_t keep : {size_t(8), size_t(40), size_t(80), size_t(110)}) {
    TempDir dir;
    SCOPED_TRACE(keep);
    auto r = import_file(draco_box(dir, keep, nothing));
    expect_refused(r, ExitCode::InvalidInput, w, "Draco");
  }
  {
    TempDir dir;
    expect_invalid(draco_box(dir, 999, [](json& d) { d["accessors"][2]["count"] = 30; }), w, "decoded 24 points");
  }
  {
    TempDir dir;
    expect_invalid(draco_box(dir, 999, [](json& d) { d["accessors"][0]["count"] = 33; }), w, "faces");
  }
  {
    TempDir dir;
    expect_invalid(draco_box(dir, 999,
                             [](json& d) {
                               d["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
                                ["attributes"]["POSITION"] = 9;
                             }),
                   w, "not in the stream");
  }
  {
    TempDir dir;
    expect_invalid(draco_box(dir, 999,
                             [](json& d) {
                               d["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
                                ["bufferView"] = 5;
                             }),
                   w, "bufferView");
  }
  {
    TempDir dir;
    expect_invalid(draco_box(dir, 999, [](json& d) { d["bufferViews"][0]["byteOffset"] = 100; }), "bufferViews[0]",
                   "outside");
  }
}

TEST(BadInputHostile, LegacyDraco2017) {
  for (const char* f : {"draco-legacy-2017/box/Box.gltf", "draco-legacy-2017/boxtextured/BoxTextured.gltf"})
    expect_invalid(asset(f), "KHR_draco_mesh_compression", "Draco");
}

}  // namespace
}  // namespace gibake::test
