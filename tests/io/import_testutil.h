// Test helpers for the glTF importer tests: temp folders and a tiny glTF writer.
#pragma once
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/gltf/import.h"

namespace gibake::test {

using nlohmann::json;
namespace fs = std::filesystem;

inline std::string assets_dir() { return GIBAKE_ASSETS_DIR; }
inline std::string asset(const std::string& rel) { return assets_dir() + "/" + rel; }

// A fresh folder under the system temp dir, removed with the object.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "gibake_import_XXXXXX").string();
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    path = mkdtemp(buf.data());
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

inline void write_file(const std::string& path, const std::string& bytes) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

inline std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

inline std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 | uint8_t(in[i + 2]);
    for (int k = 3; k >= 0; --k) out += t[(v >> (6 * k)) & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16;
    out += t[(v >> 18) & 63], out += t[(v >> 12) & 63], out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8;
    out += t[(v >> 18) & 63], out += t[(v >> 12) & 63], out += t[(v >> 6) & 63], out += '=';
  }
  return out;
}

// Builds a glTF document with one binary buffer.
struct GltfBuilder {
  std::string bin;
  json doc;
  GltfBuilder() {
    doc = {{"asset", {{"version", "2.0"}}},
           {"buffers", json::array()},
           {"bufferViews", json::array()},
           {"accessors", json::array()},
           {"meshes", json::array()},
           {"nodes", json::array()},
           {"scenes", json::array({{{"nodes", json::array()}}})},
           {"scene", 0}};
  }
  template <typename T>
  int view(const std::vector<T>& data, int stride = 0) {
    while (bin.size() % 4) bin += '\0';
    size_t off = bin.size();
    bin.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(T));
    json v = {{"buffer", 0}, {"byteOffset", off}, {"byteLength", data.size() * sizeof(T)}};
    if (stride) v["byteStride"] = stride;
    doc["bufferViews"].push_back(v);
    return int(doc["bufferViews"].size() - 1);
  }
  int accessor(int view, int ctype, size_t count, const std::string& type, bool normalized = false) {
    json a = {{"bufferView", view}, {"componentType", ctype}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size() - 1);
  }
  int floats(const std::vector<float>& v, const std::string& type, int comps) {
    return accessor(view(v), 5126, v.size() / size_t(comps), type);
  }
  int indices(const std::vector<uint16_t>& v) { return accessor(view(v), 5123, v.size(), "SCALAR"); }
  int mesh(const json& primitive) {
    doc["meshes"].push_back({{"primitives", json::array({primitive})}});
    return int(doc["meshes"].size() - 1);
  }
  int node(const json& n, bool root = true) {
    doc["nodes"].push_back(n);
    int i = int(doc["nodes"].size() - 1);
    if (root) doc["scenes"][0]["nodes"].push_back(i);
    return i;
  }
  // Writes name.gltf into dir; the buffer as a data: URI or as name.bin beside it.
  std::string write(const TempDir& dir, const std::string& name, bool data_uri = true) {
    while (bin.size() % 4) bin += '\0';
    json d = doc;
    std::string uri = "data:application/octet-stream;base64," + base64(bin);
    if (!data_uri && !bin.empty()) {
      write_file(dir.file(name + ".bin"), bin);
      uri = name + ".bin";
    }
    if (bin.empty()) d.erase("buffers");
    else d["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", uri}}});
    std::string path = dir.file(name + ".gltf");
    write_file(path, d.dump());
    return path;
  }
};

// A unit cube (24 corner-duplicated vertices would hide nothing here: 8 shared vertices),
// triangles CCW seen from outside.
inline void unit_cube(std::vector<float>& pos, std::vector<uint16_t>& idx) {
  pos.clear();
  idx.clear();
  for (int i = 0; i < 8; ++i) {
    pos.push_back(i & 1 ? 1.f : -1.f);
    pos.push_back(i & 2 ? 1.f : -1.f);
    pos.push_back(i & 4 ? 1.f : -1.f);
  }
  // Faces as quads a,b,c,d in CCW order seen from outside.
  const uint16_t q[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (auto& f : q) idx.insert(idx.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
}

// Adds the unit cube as a mesh (POSITION + indices, plus `extra` primitive fields); returns its index.
inline int add_unit_cube_mesh(GltfBuilder& g, const nlohmann::json& extra = nlohmann::json::object()) {
  std::vector<float> p;
  std::vector<uint16_t> i;
  unit_cube(p, i);
  nlohmann::json primitive = {{"attributes", {{"POSITION", g.floats(p, "VEC3", 3)}}}, {"indices", g.indices(i)}};
  primitive.update(extra);
  return g.mesh(primitive);
}

struct ImportResult {
  Status status;
  Scene scene;
  std::vector<std::string> warnings;
};

inline ImportResult import_file(const std::string& path, ImportOptions opt = {},
                                unsigned threads = 0) {
  ImportResult r;
  Context ctx;
  ctx.threads = threads;
  ctx.warn = [&r](const std::string& w) { r.warnings.push_back(w); };
  r.status = import_scene(path, opt, ctx, r.scene);
  return r;
}

}  // namespace gibake::test
