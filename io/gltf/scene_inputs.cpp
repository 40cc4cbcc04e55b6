#include "io/gltf/scene_inputs.h"

#include <sys/stat.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "io/gltf/gltf_fs.h"
#include "io/gltf/gltf_internal.h"

namespace gibake {
namespace {

// A .gltf larger than this (data: URIs inline) is not pre-read: its buffers are then embedded, and
// reading it twice would cost more than the check saves.
constexpr uint64_t kMaxPreRead = uint64_t(64) << 20;

uint32_t le32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The JSON text of a .gltf, or of a .glb's first chunk; empty when neither can be read cheaply.
std::string read_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  unsigned char head[20] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  const size_t got = size_t(in.gcount());
  if (got >= 4 && std::memcmp(head, "glTF", 4) == 0) {
    if (got < 20 || le32(head + 16) != 0x4E4F534Au) return {};
    const uint32_t length = le32(head + 12);
    if (length > kMaxPreRead) return {};
    std::string json(length, '\0');
    in.read(json.data(), length);
    return size_t(in.gcount()) == length ? json : std::string();
  }
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || uint64_t(st.st_size) > kMaxPreRead) return {};
  std::string json(reinterpret_cast<const char*>(head), got);
  json.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return json;
}

std::string canonical_folder(const std::string& path) {
  std::unique_ptr<char, decltype(&std::free)> r(realpath(path.c_str(), nullptr), &std::free);
  if (!r) return {};
  const std::string real(r.get());
  return real.substr(0, real.rfind('/'));
}

}  // namespace

Status refuse_bake_file_as_scene(const std::string& scene_path) {
  static const char kBakeMagic[8] = {'G', 'I', 'B', 'A', 'K', 'E', 0, 0x1a};  // docs/FORMAT.md
  char head[8] = {};
  std::ifstream in(scene_path, std::ios::binary);
  if (!in.read(head, sizeof(head)) || std::memcmp(head, kBakeMagic, sizeof(head)) != 0) return Status::ok();
  return Status::invalid(scene_path, "", "a gibake bake file, not a scene: give the .gltf or .glb to read");
}

std::vector<NamedPath> scene_input_files(const std::string& scene_path) {
  std::vector<NamedPath> files{{"scene", scene_path}};
  const std::string base = canonical_folder(scene_path);
  if (base.empty()) return files;
  const nlohmann::json doc = nlohmann::json::parse(read_json(scene_path), nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return files;
  for (const char* section : {"buffers", "images"}) {
    const auto list = doc.find(section);
    if (list == doc.end() || !list->is_array()) continue;
    for (size_t i = 0; i < list->size(); ++i) {
      const auto& entry = (*list)[i];
      if (!entry.is_object() || !entry.contains("uri") || !entry["uri"].is_string()) continue;
      const std::string uri = entry["uri"].get<std::string>();
      if (uri.compare(0, 5, "data:") == 0) continue;
      std::string resolved, what;
      if (gltf::resolve_relative(base, gltf::uri_decode(uri), resolved, what))
        files.push_back({gltf::at(section, i), resolved});
    }
  }
  return files;
}

}  // namespace gibake
