#include "io/bakefile/input_digest.h"

#include <xxhash.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace gibake {

std::string hash_text(uint64_t hash) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(hash));
  return text;
}

namespace {

class Hasher {
 public:
  Hasher() : state_(XXH3_createState(), &XXH3_freeState) { XXH3_64bits_reset(state_.get()); }
  void bytes(const void* data, size_t size) {
    const uint64_t n = size;
    XXH3_64bits_update(state_.get(), &n, sizeof n);  // length first: no two sequences run together
    if (size) XXH3_64bits_update(state_.get(), data, size);
  }
  template <class T>
  void vec(const std::vector<T>& v) { bytes(v.data(), v.size() * sizeof(T)); }
  template <class T>
  void pod(const T& v) { bytes(&v, sizeof v); }
  // Each value in turn, as pod() and vec() hash it one by one.
  template <class... T>
  void pods(const T&... v) { (pod(v), ...); }
  template <class... T>
  void vecs(const std::vector<T>&... v) { (vec(v), ...); }
  void text(const std::string& s) { bytes(s.data(), s.size()); }
  uint64_t digest() const { return XXH3_64bits_digest(state_.get()); }

 private:
  std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state_;
};

void texture_ref(Hasher& h, const TextureRef& t) {
  h.pods(t.texture, t.texcoord, t.offset, t.scale, t.rotation, t.has_transform);
}

// What the bakers read of a material: names, metallic and roughness (carried, never traced) are left out.
void material(Hasher& h, const Material& m) {
  h.pod(m.base_color);
  texture_ref(h, m.base_color_texture);
  h.pods(m.emissive, m.emissive_strength);
  texture_ref(h, m.emissive_texture);
  h.pods(m.alpha_mode, m.alpha_cutoff, m.double_sided, m.transmission);
  texture_ref(h, m.transmission_texture);
}

std::string lower_extension(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

std::string file_kind(const std::string& path, size_t index) {
  if (index == 0) return "scene";
  const std::string e = lower_extension(path);
  if (e == ".png" || e == ".jpg" || e == ".jpeg" || e == ".webp" || e == ".ktx2" || e == ".bmp" || e == ".gif")
    return "image";
  return "buffer";
}

bool parse_hex(const nlohmann::json& j, uint64_t& out) {
  if (!j.is_string()) return false;
  const std::string s = j.get<std::string>();
  if (s.size() != 18 || s.compare(0, 2, "0x") != 0) return false;
  try {
    out = std::stoull(s.substr(2), nullptr, 16);
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

std::string canonical(const std::string& settings) {
  const nlohmann::json j = nlohmann::json::parse(settings, nullptr, false);
  return j.is_discarded() ? settings : j.dump();
}

constexpr const char* kParts[] = {"geometry", "materials", "textures", "lights"};

uint64_t InputDigest::*part_member(size_t i) {
  static uint64_t InputDigest::*const members[] = {&InputDigest::geometry, &InputDigest::materials,
                                                   &InputDigest::textures, &InputDigest::lights};
  return members[i];
}

}  // namespace

InputDigest digest_scene(const Scene& scene) {
  InputDigest d;
  Hasher g;
  g.vecs(scene.positions, scene.normals, scene.uvs, scene.colors, scene.indices, scene.tri_material);
  d.geometry = g.digest();
  Hasher m;
  m.pod(scene.materials.size());
  for (const Material& x : scene.materials) material(m, x);
  d.materials = m.digest();
  Hasher t;
  t.pod(scene.textures.size());
  for (const Texture& x : scene.textures) {
    t.pods(x.width, x.height, x.wrap_s, x.wrap_t);
    t.vec(x.rgba8);
  }
  d.textures = t.digest();
  Hasher l;
  l.pod(scene.lights.size());
  for (const Light& x : scene.lights)  // the name is left out: nothing reads it
    l.pods(x.type, x.color, x.intensity, x.position, x.direction, x.range, x.inner_cone_angle, x.outer_cone_angle);
  d.lights = l.digest();
  return d;
}

Status digest_files(const std::vector<std::string>& input_files, InputDigest& digest) {
  digest.files.clear();
  const std::filesystem::path base =
      input_files.empty() ? std::filesystem::path() : std::filesystem::path(input_files[0]).parent_path();
  std::vector<char> buffer(1 << 20);
  for (size_t i = 0; i < input_files.size(); ++i) {
    std::ifstream in(input_files[i], std::ios::binary);
    if (!in) return Status::io(input_files[i], "cannot open input for hashing");
    std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state(XXH3_createState(), &XXH3_freeState);
    XXH3_64bits_reset(state.get());
    while (in) {
      in.read(buffer.data(), std::streamsize(buffer.size()));
      if (in.gcount() > 0) XXH3_64bits_update(state.get(), buffer.data(), size_t(in.gcount()));
    }
    if (in.bad()) return Status::io(input_files[i], "read failed while hashing");
    const std::filesystem::path p(input_files[i]);
    std::string rel = i == 0 ? p.filename().generic_string() : p.lexically_relative(base).generic_string();
    if (rel.empty() || rel.compare(0, 2, "..") == 0) rel = p.filename().generic_string();
    digest.files.push_back({rel, file_kind(input_files[i], i), XXH3_64bits_digest(state.get())});
  }
  return Status::ok();
}

uint64_t content_input_hash(const InputDigest& d, const std::string& settings, const std::string& version) {
  Hasher h;
  h.text(InputDigest::kScheme);
  for (size_t i = 0; i < 4; ++i) h.pod(d.*part_member(i));
  h.text(canonical(settings));
  h.text(version);
  return h.digest();
}

nlohmann::json input_digest_json(const InputDigest& d) {
  nlohmann::json files = nlohmann::json::array();
  for (const InputDigest::File& f : d.files)
    files.push_back({{"path", f.path}, {"kind", f.kind}, {"bytes", hash_text(f.bytes)}});
  nlohmann::json j{{"scheme", InputDigest::kScheme}, {"files", files}};
  for (size_t i = 0; i < 4; ++i) j[kParts[i]] = hash_text(d.*part_member(i));
  return j;
}

bool input_digest_from_json(const nlohmann::json& j, InputDigest& out) {
  out = InputDigest{};
  if (!j.is_object() || j.value("scheme", std::string()) != InputDigest::kScheme) return false;
  for (size_t i = 0; i < 4; ++i)
    if (!j.contains(kParts[i]) || !parse_hex(j[kParts[i]], out.*part_member(i))) return false;
  if (!j.contains("files") || !j["files"].is_array()) return false;
  for (const nlohmann::json& f : j["files"]) {
    InputDigest::File file;
    if (!f.is_object() || !f.contains("path") || !f["path"].is_string() || !f.contains("bytes") ||
        !parse_hex(f["bytes"], file.bytes))
      return false;
    file.path = f["path"].get<std::string>();
    file.kind = f.value("kind", std::string("file"));
    out.files.push_back(std::move(file));
  }
  return true;
}

InputChanges compare_digests(const InputDigest& baked, const InputDigest& now) {
  InputChanges c;
  for (size_t i = 0; i < 4; ++i)
    if (baked.*part_member(i) != now.*part_member(i)) c.parts.push_back(kParts[i]);
  auto named = [](const InputDigest::File& f) { return f.path + " (" + f.kind + ")"; };
  for (const InputDigest::File& f : now.files) {
    auto it = std::find_if(baked.files.begin(), baked.files.end(),
                           [&](const InputDigest::File& b) { return b.path == f.path; });
    if (it == baked.files.end()) c.files_added.push_back(named(f));
    else if (it->bytes != f.bytes) c.files_changed.push_back(named(f));
  }
  for (const InputDigest::File& b : baked.files)
    if (std::none_of(now.files.begin(), now.files.end(), [&](const InputDigest::File& f) { return f.path == b.path; }))
      c.files_removed.push_back(named(b));
  return c;
}

}  // namespace gibake
