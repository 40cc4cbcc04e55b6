// The tinygltf translation unit: GLB framing checks, URI pre-checks, callbacks, load.
#define TINYGLTF_IMPLEMENTATION
// External image files are read by accept_images (in parallel), not by tinygltf's parser.
#define TINYGLTF_NO_EXTERNAL_IMAGE
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include "io/gltf/gltf_tiny.h"
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <sys/stat.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>

#include "io/gltf/gltf_fs.h"
#include "io/gltf/gltf_internal.h"
#include "io/gltf/gltf_load.h"
#include "io/gltf/gltf_types.h"
#include "io/gltf/scene_inputs.h"
#include "io/gltf/texture_decode.h"

namespace gibake::gltf {
namespace {

// An image's encoded bytes, kept until parse() has succeeded: tinygltf frees a data: URI's or a
// bufferView's bytes once the image callback returns, and decoding there would be serial.
struct PendingImage {
  size_t index = 0;  // into Model::images
  std::vector<unsigned char> bytes;
};

struct LoadState {
  FsState fs;
  ImageBudget images;
  std::vector<PendingImage> embedded;  // data: URI and bufferView images, as tinygltf hands them over
  std::vector<PendingImage> pending;   // accepted for decoding, in image order
  const Context* ctx = nullptr;
  const tinygltf::Model* model = nullptr;
  const std::function<bool()>* cancelled = nullptr;  // ImportOptions::cancelled, when set
};

uint32_t read_u32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

bool is_glb(const std::vector<unsigned char>& bytes) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

bool is_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// Checks the GLB header and chunk framing; `length` is the declared total length.
Status check_glb(const std::string& file, const std::vector<unsigned char>& b, uint32_t& length,
                 std::string& json) {
  if (b.size() < 20) return Status::invalid(file, "GLB header", "file too short for a GLB header");
  if (read_u32(&b[4]) != 2)
    return Status::invalid(file, "GLB header",
                           "unsupported GLB version " + std::to_string(read_u32(&b[4])));
  length = read_u32(&b[8]);
  if (length > b.size() || length < 20)
    return Status::invalid(file, "GLB header",
                           "declared length " + std::to_string(length) +
                               " does not match the file size " + std::to_string(b.size()));
  uint64_t c0 = read_u32(&b[12]);
  if (read_u32(&b[16]) != 0x4E4F534Au || c0 == 0 || 20 + c0 > length)
    return Status::invalid(file, "GLB JSON chunk", "missing or truncated JSON chunk");
  uint64_t pos = 20 + c0;
  if (pos < length) {
    if (pos + 8 > length) return Status::invalid(file, "GLB BIN chunk", "truncated chunk header");
    uint64_t c1 = read_u32(&b[pos]);
    if (pos + 8 + c1 > length)
      return Status::invalid(file, "GLB BIN chunk", "chunk runs past the end of the file");
  }
  json.assign(reinterpret_cast<const char*>(&b[20]), size_t(c0));
  return Status::ok();
}

// One buffers[i].uri / images[i].uri: data: must be one tinygltf decodes, paths must stay inside.
// A data: URI's base64 text: only the alphabet, '=' padding at the end alone, and for a buffer at
// least its byteLength of bytes (`byte_length` < 0: none given). Checked here, where the error can
// name the place; the decoder would only say that it failed.
Status check_base64(const std::string& file, const std::string& where, const std::string& uri, double byte_length) {
  const size_t start = uri.find(";base64,") + 8;
  size_t end = uri.size();
  while (end > start && end + 2 > uri.size() && uri[end - 1] == '=') --end;
  for (size_t i = start; i < end; ++i) {
    const unsigned char c = static_cast<unsigned char>(uri[i]);
    if (!std::isalnum(c) && c != '+' && c != '/')
      return Status::invalid(file, where,
                             "data: URI is not valid base64 (character " + std::to_string(i - start) + " of its data)");
  }
  const double bytes = double(end - start) * 3.0 / 4.0;
  if (byte_length >= 0.0 && std::floor(bytes) < byte_length)
    return Status::invalid(file, where,
                           "data: URI holds " + std::to_string(uint64_t(bytes)) +
                               " bytes, fewer than the buffer's byteLength " + std::to_string(uint64_t(byte_length)));
  return Status::ok();
}

Status check_uri(const std::string& file, const std::string& base, const std::string& where, const std::string& uri,
                 bool is_buffer, double byte_length) {
  if (uri.compare(0, 5, "data:") == 0) {
    if (is_supported_data_uri(uri)) return check_base64(file, where, uri, is_buffer ? byte_length : -1.0);
    return Status::invalid(file, where, "unsupported data: URI (only base64 with a known media type)");
  }
  std::string resolved, what;
  if (!resolve_relative(base, uri_decode(uri), resolved, what)) return Status::invalid(file, where, what);
  if (is_buffer && !is_file(resolved)) return Status::io(resolved, "cannot open buffer file (" + where + ")");
  return Status::ok();
}

const char* const kSupportedRequired[] = {
    "KHR_draco_mesh_compression", "KHR_mesh_quantization", "KHR_texture_transform",
    "KHR_materials_emissive_strength", "KHR_lights_punctual", "KHR_materials_unlit"};

Status check_required_extensions(const std::string& file, const nlohmann::json& doc) {
  auto it = doc.find("extensionsRequired");
  if (it == doc.end() || !it->is_array()) return Status::ok();
  for (size_t i = 0; i < it->size(); ++i) {
    const auto& e = (*it)[i];
    if (!e.is_string()) continue;
    bool known = false;
    for (const char* s : kSupportedRequired) known = known || e.get<std::string>() == s;
    if (!known)
      return Status::invalid(file, at("extensionsRequired", i),
                             "required extension " + e.get<std::string>() + " is not supported");
  }
  return Status::ok();
}

// tinygltf refuses an indices accessor without a bufferView (Draco primitives declare theirs that
// way; the spec allows zero-filled accessors). Such an index moves into the primitive's
// extensions as "GIBAKE_indices" (see primitive_indices()). True when the document changed.
bool stash_viewless_indices(nlohmann::json& doc) {
  auto meshes = doc.find("meshes");
  auto accessors = doc.find("accessors");
  if (meshes == doc.end() || !meshes->is_array() || accessors == doc.end() || !accessors->is_array()) return false;
  bool changed = false;
  for (auto& mesh : *meshes) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (auto& p : mesh["primitives"]) {
      if (!p.is_object() || !p.contains("indices") || !p["indices"].is_number_unsigned()) continue;
      uint64_t i = p["indices"].get<uint64_t>();
      if (i >= accessors->size() || !(*accessors)[size_t(i)].is_object() ||
          (*accessors)[size_t(i)].contains("bufferView"))
        continue;
      if (!p.contains("extensions")) p["extensions"] = nlohmann::json::object();
      if (!p["extensions"].is_object()) continue;
      p["extensions"]["GIBAKE_indices"] = {{"accessor", i}};
      p.erase("indices");
      changed = true;
    }
  }
  return changed;
}

// Images in data: URIs of a media type tinygltf does not decode (e.g. image/webp) are replaced
// by an undecodable stub, so the image is skipped with a warning instead of failing the file.
bool stub_unknown_data_images(nlohmann::json& doc, const std::string& file, const Context& ctx) {
  auto images = doc.find("images");
  if (images == doc.end() || !images->is_array()) return false;
  bool changed = false;
  for (size_t i = 0; i < images->size(); ++i) {
    auto& img = (*images)[i];
    if (!img.is_object() || !img.contains("uri") || !img["uri"].is_string()) continue;
    std::string uri = img["uri"].get<std::string>();
    if (uri.compare(0, 5, "data:") != 0 || is_supported_data_uri(uri)) continue;
    ctx.warning(file + ": " + at("images", i) + ": data: URI media type not supported; image ignored");
    img["uri"] = "data:text/plain;base64,AAAA";
    changed = true;
  }
  return changed;
}

// URIs are checked here, with their place in the file, before tinygltf opens anything.
// `json` is rewritten when Draco indices had to be stashed.
// tinygltf converts extensions/extras recursively: a hostile nesting depth would overflow the
// stack, so it is bounded before any parser sees the text.
constexpr int kMaxJsonDepth = 128;

bool json_depth_ok(const std::string& text) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) return false;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return true;
}

// In a .gltf, a buffer without uri has no data anywhere (only a GLB's first buffer may omit it).
Status check_buffer_uris(const std::string& file, const nlohmann::json& doc, bool glb) {
  auto it = doc.find("buffers");
  if (it == doc.end() || !it->is_array()) return Status::ok();
  for (size_t i = 0; i < it->size(); ++i) {
    const auto& b = (*it)[i];
    if (b.is_object() && !b.contains("uri") && !(glb && i == 0))
      return Status::invalid(file, at("buffers", i), "buffer has no uri, so its data is not available");
  }
  return Status::ok();
}

// "line L, column C" of the byte nlohmann's parse error gives (1-based: the byte after the last one
// read, where the text stops making sense).
std::string text_place(const std::string& text, size_t byte) {
  const size_t end = std::min(text.size(), byte > 0 ? byte - 1 : 0);
  size_t line = 1, column = 1;
  for (size_t i = 0; i < end; ++i) {
    if (text[i] == '\n')
      ++line, column = 1;
    else
      ++column;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

Status prescan(const std::string& file, const std::string& base, const Context& ctx, bool glb, std::string& json) {
  if (!json_depth_ok(json))
    return Status::invalid(file, "JSON", "nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json);
  } catch (const nlohmann::json::parse_error& e) {
    return Status::invalid(file, "JSON", "not valid JSON at " + text_place(json, e.byte));
  } catch (const nlohmann::json::exception& e) {  // a number beyond a double's range, and the like
    const std::string what = e.what();
    return Status::invalid(file, "JSON", "not valid JSON: " + what.substr(what.find("] ") + 2));
  }
  if (!doc.is_object()) return Status::invalid(file, "JSON", "top level is not an object");
  GIBAKE_TRY(check_json_types(file, doc, ctx));
  GIBAKE_TRY(check_required_extensions(file, doc));
  GIBAKE_TRY(check_buffer_uris(file, doc, glb));
  bool changed = stub_unknown_data_images(doc, file, ctx);
  for (const char* section : {"buffers", "images"}) {
    auto it = doc.find(section);
    if (it == doc.end() || !it->is_array()) continue;
    for (size_t i = 0; i < it->size(); ++i) {
      const auto& e = (*it)[i];
      if (!e.is_object()) continue;
      auto u = e.find("uri");
      if (u == e.end() || !u->is_string()) continue;
      auto length = e.find("byteLength");
      const double byte_length = length != e.end() && length->is_number() ? length->get<double>() : -1.0;
      GIBAKE_TRY(check_uri(file, base, at(section, i) + ".uri", u->get<std::string>(), section[0] == 'b', byte_length));
    }
  }
  if (stash_viewless_indices(doc) || changed) json = doc.dump();
  return Status::ok();
}

// The file an image's bytes came from, for error messages.
std::string image_file(const LoadState& st, const tinygltf::Image& image) {
  if (image.uri.empty() || image.uri.compare(0, 5, "data:") == 0) return st.fs.user_file;
  std::string resolved, what;
  if (resolve_relative(st.fs.base_dir, uri_decode(image.uri), resolved, what)) return resolved;
  return st.fs.user_file;
}

// Images stored in a bufferView: tinygltf hands us a pointer without checking the range.
bool image_view_in_range(const tinygltf::Model& m, int view) {
  if (view < 0) return true;
  if (size_t(view) >= m.bufferViews.size()) return false;
  const auto& v = m.bufferViews[size_t(view)];
  if (v.buffer < 0 || size_t(v.buffer) >= m.buffers.size()) return false;
  size_t size = m.buffers[size_t(v.buffer)].data.size();
  return v.byteOffset <= size && v.byteLength <= size - v.byteOffset;
}

bool load_image(tinygltf::Image* image, const int index, std::string* err, std::string*, int, int,
                const unsigned char* bytes, int size, void* user) {
  auto* st = static_cast<LoadState*>(user);
  std::string where = at("images", size_t(index));
  if (!image_view_in_range(*st->model, image->bufferView)) {
    st->fs.error = Status::invalid(st->fs.user_file, where, "bufferView range lies outside its buffer");
    if (err) *err += "refused\n";
    return false;
  }
  // Checked with every other image after parse(), in image order (accept_images).
  st->embedded.push_back({size_t(index), std::vector<unsigned char>(bytes, bytes + size_t(size < 0 ? 0 : size))});
  return true;
}

// Checks image `index`'s header against the limits and the pixel budget (in image order, so the
// budget does not depend on scheduling) and queues it for decoding; an error refuses the file.
Status accept_image(LoadState& st, tinygltf::Image& image, size_t index, std::vector<unsigned char>&& bytes) {
  ImageHeader header;
  std::string warning;
  GIBAKE_TRY(check_image_header(bytes.data(), bytes.size(), image_file(st, image), at("images", index), st.images,
                                header, warning));
  if (!warning.empty()) st.ctx->warning(st.fs.user_file + ": " + warning);
  image.width = header.width;
  image.height = header.height;
  image.component = 4;
  image.bits = 8;
  image.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image.image.clear();  // decoded by decode_pending()
  if (st.images.decode && header.width > 0) st.pending.push_back({index, std::move(bytes)});
  return Status::ok();
}

// An image file named by a uri, read beside the others.
struct ExternalImage {
  size_t index = 0;
  std::string path;
  uint64_t cap = 0;  // the byte limit it is read under: what reading the files in order would leave
  std::vector<unsigned char> bytes;
  Status read;
};

// The image files tinygltf leaves to us (TINYGLTF_NO_EXTERNAL_IMAGE): a missing file is ignored
// with a warning, as tinygltf would; the byte budget and the file list follow image order; the
// reads run in parallel. Then every image, embedded or not, is checked in image order.
Status accept_images(LoadState& st, tinygltf::Model& model) {
  std::vector<ExternalImage> files;
  for (size_t i = 0; i < model.images.size(); ++i) {
    const tinygltf::Image& im = model.images[i];
    if (im.bufferView >= 0 || im.uri.empty() || im.uri.compare(0, 5, "data:") == 0) continue;
    std::string resolved, what;
    if (!resolve_relative(st.fs.base_dir, uri_decode(im.uri), resolved, what) || !is_file(resolved)) {
      std::error_code ec;
      const bool exists = !resolved.empty() && std::filesystem::exists(resolved, ec);
      st.ctx->warning(st.fs.user_file + ": " + at("images", i) + ": image file '" + im.uri +
                      (exists ? "' is not a regular file" : "' not found") + "; image ignored");
      if (!resolved.empty() && !exists) st.fs.files_missing.push_back(resolved);
      continue;
    }
    ExternalImage f;
    f.index = i;
    f.path = resolved;
    files.push_back(std::move(f));
  }
  const ImportLimits& limits = *st.fs.limits;
  uint64_t total = st.fs.total_bytes;
  for (ExternalImage& f : files) {
    f.cap = std::min(limits.max_file_bytes,
                     limits.max_total_buffer_bytes - std::min(total, limits.max_total_buffer_bytes));
    struct stat sb {};
    if (::stat(f.path.c_str(), &sb) == 0 && uint64_t(sb.st_size) <= f.cap) total += uint64_t(sb.st_size);
  }
  tbb::task_arena arena(st.ctx->threads > 0 ? int(st.ctx->threads) : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), files.size(), [&](size_t k) {
      files[k].read = read_file_capped(files[k].path, files[k].cap, "", files[k].bytes);
    }, tbb::simple_partitioner());
  });
  std::vector<std::vector<unsigned char>*> bytes_of(model.images.size(), nullptr);
  for (PendingImage& e : st.embedded) bytes_of[e.index] = &e.bytes;
  for (ExternalImage& f : files) {
    GIBAKE_TRY(f.read);  // the first failure in image order, as a one-by-one read would stop there
    st.fs.total_bytes += f.bytes.size();
    st.fs.files_read.push_back(f.path);
    bytes_of[f.index] = &f.bytes;
  }
  for (size_t i = 0; i < model.images.size(); ++i)
    if (bytes_of[i]) GIBAKE_TRY(accept_image(st, model.images[i], i, std::move(*bytes_of[i])));
  st.embedded.clear();
  return Status::ok();
}

// A failed decode leaves the image as an unreadable one: no size, no pixels.
void mark_undecodable(tinygltf::Image& image) {
  image.width = 0;
  image.height = 0;
  image.image.clear();
}

// One pending image into its Model::images entry; false when stb could not decode it.
bool decode_one(PendingImage& p, tinygltf::Image& image) {
  ImageHeader header{image.width, image.height};
  bool ok = decode_rgba8(p.bytes.data(), p.bytes.size(), header, image.image);
  std::vector<unsigned char>().swap(p.bytes);  // the encoded copy is not needed any more
  return ok;
}

// Decodes the accepted images concurrently, one task each (their sizes differ a lot). Each task
// writes only its own Model::images entry; warnings wait for the loop and go out in image order on
// this thread, because Context callbacks are not thread-safe and the output must not depend on
// scheduling.
// Images some material reads for what the bakers use (base colour with its alpha, emission,
// transmission).
// Normal, occlusion and metallic-roughness maps are checked but never decoded: a Lambertian baker
// does not read them, and decoding them would be a large share of a textured scene's import.
std::vector<char> images_in_use(const tinygltf::Model& model) {
  std::vector<char> used(model.images.size(), 0);
  auto mark = [&](int texture) {
    if (texture < 0 || size_t(texture) >= model.textures.size()) return;
    const int source = model.textures[size_t(texture)].source;
    if (source >= 0 && size_t(source) < used.size()) used[size_t(source)] = 1;
  };
  for (const tinygltf::Material& m : model.materials) {
    mark(m.pbrMetallicRoughness.baseColorTexture.index);
    mark(m.emissiveTexture.index);
    const auto glass = m.extensions.find("KHR_materials_transmission");  // its red channel
    if (glass != m.extensions.end() && glass->second.IsObject()) {
      const tinygltf::Value& t = glass->second.Get("transmissionTexture");
      const tinygltf::Value& index = t.IsObject() ? t.Get("index") : t;
      if (index.IsInt()) mark(index.GetNumberAsInt());
    }
  }
  return used;
}

void decode_pending(LoadState& st, tinygltf::Model& model, const std::function<void()>& beside) {
  const std::vector<char> used = images_in_use(model);
  st.pending.erase(std::remove_if(st.pending.begin(), st.pending.end(),
                                  [&](const PendingImage& p) { return !used[p.index]; }),
                   st.pending.end());
  std::vector<char> failed(st.pending.size(), 0);
  tbb::task_arena arena(st.ctx->threads > 0 ? int(st.ctx->threads) : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::task_group decoding;
    decoding.run([&] {
      tbb::parallel_for(
          size_t(0), st.pending.size(),
          [&](size_t i) {
            if (st.cancelled && (*st.cancelled)()) return;  // the import fails anyway: see import_impl
            failed[i] = !decode_one(st.pending[i], model.images[st.pending[i].index]);
          },
          tbb::simple_partitioner());
    });
    if (beside) beside();  // must not throw: the caller wraps it
    decoding.wait();
  });
  for (size_t i = 0; i < st.pending.size(); ++i) {
    if (!failed[i]) continue;
    mark_undecodable(model.images[st.pending[i].index]);
    const tinygltf::Image& im = model.images[st.pending[i].index];
    const bool external = im.bufferView < 0 && !im.uri.empty() && im.uri.compare(0, 5, "data:") != 0;
    st.ctx->warning(st.fs.user_file + ": " + at("images", st.pending[i].index) +
                    (external ? " ('" + im.uri + "')" : std::string()) + ": image could not be decoded; image ignored");
  }
  st.pending.clear();
}

// A message's first line, cut short: tinygltf's messages may quote a whole data: URI.
std::string first_line(const std::string& s) {
  constexpr size_t kMostChars = 200;
  std::string line = s.substr(0, s.find('\n'));
  if (line.size() > kMostChars) line = line.substr(0, kMostChars) + "...";
  return line.empty() ? std::string("tinygltf could not parse the file") : line;
}

// A GLB with a new JSON chunk and the original BIN chunk (and anything after it).
std::vector<unsigned char> rebuild_glb(const std::vector<unsigned char>& b, uint32_t length, std::string json) {
  while (json.size() % 4) json += ' ';
  size_t rest = 20 + size_t(read_u32(&b[12]));
  std::vector<unsigned char> out;
  auto u32 = [&out](uint32_t v) { for (int k = 0; k < 4; ++k) out.push_back(uint8_t(v >> (8 * k))); };
  out.insert(out.end(), b.begin(), b.begin() + 8);
  u32(uint32_t(20 + json.size() + (length - rest)));
  u32(uint32_t(json.size()));
  u32(0x4E4F534Au);
  out.insert(out.end(), json.begin(), json.end());
  out.insert(out.end(), b.begin() + long(rest), b.begin() + long(length));
  return out;
}

Status parse(LoadState& st, const std::vector<unsigned char>& bytes, bool glb, uint32_t glb_length,
             const std::string& json, tinygltf::Model& model) {
  tinygltf::TinyGLTF loader;
  tinygltf::FsCallbacks cb{&fs_file_exists, &fs_expand_file_path, &fs_read_whole_file,
                           &fs_write_whole_file, &st.fs};
  loader.SetFsCallbacks(cb);
  loader.SetImageLoader(&load_image, &st);
  st.model = &model;
  std::string err, warn;
  bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), glb_length, st.fs.base_dir)
                : loader.LoadASCIIFromString(&model, &err, &warn, json.data(),
                                             static_cast<unsigned int>(json.size()), st.fs.base_dir);
  if (!st.fs.error.is_ok()) return st.fs.error;
  if (!ok) return Status::invalid(st.fs.user_file, "glTF", first_line(err));
  if (!warn.empty()) st.ctx->warning(st.fs.user_file + ": " + first_line(warn));
  return Status::ok();
}

std::string canonical_path(const std::string& path) {
  std::unique_ptr<char, decltype(&std::free)> r(realpath(path.c_str(), nullptr), &std::free);
  return r ? std::string(r.get()) : std::string();
}

}  // namespace

Status load_model(const std::string& path, const ImportOptions& options, const Context& ctx, tinygltf::Model& model,
                  std::vector<std::string>& files_read, std::vector<std::string>& files_missing,
                  const std::function<void()>& beside) {
  std::string real = canonical_path(path);
  if (real.empty()) return Status::io(path, std::string("cannot open file: ") + std::strerror(errno));
  std::vector<unsigned char> bytes;
  GIBAKE_TRY(read_file_capped(real, options.limits.max_file_bytes, "", bytes));
  if (bytes.size() > UINT_MAX) return Status::invalid(path, "", "file too large");
  LoadState st;
  st.fs.base_dir = real.substr(0, real.rfind('/'));
  st.fs.user_file = path;
  st.fs.limits = &options.limits;
  st.images.limits = &options.limits;
  st.images.decode = options.load_textures;
  if (options.cancelled) st.cancelled = &options.cancelled;
  st.ctx = &ctx;
  files_read.push_back(real);
  GIBAKE_TRY(refuse_bake_file_as_scene(path));  // named as what it is, not parsed as glTF JSON
  bool glb = is_glb(bytes);
  if (!glb && named_glb(path)) return Status::invalid(path, "GLB header", not_glb_text(bytes));
  uint32_t glb_length = 0;
  std::string json;
  if (glb)
    GIBAKE_TRY(check_glb(path, bytes, glb_length, json));
  else
    json.assign(bytes.begin(), bytes.end());
  std::string original = json;
  GIBAKE_TRY(prescan(path, st.fs.base_dir, ctx, glb, json));
  if (glb && json != original) {
    bytes = rebuild_glb(bytes, glb_length, json);
    if (bytes.size() > UINT_MAX) return Status::invalid(path, "", "file too large");
    glb_length = uint32_t(bytes.size());
  }
  Status s = parse(st, bytes, glb, glb_length, json, model);
  if (s.is_ok()) s = accept_images(st, model);
  files_read.insert(files_read.end(), st.fs.files_read.begin(), st.fs.files_read.end());
  files_missing.insert(files_missing.end(), st.fs.files_missing.begin(), st.fs.files_missing.end());
  if (!s.is_ok()) return s;
  std::exception_ptr beside_error;
  decode_pending(st, model, [&] {
    if (!beside) return;
    try {
      beside();
    } catch (...) {
      beside_error = std::current_exception();  // rethrown once the decode has finished
    }
  });
  if (beside_error) std::rethrow_exception(beside_error);
  return Status::ok();
}

}  // namespace gibake::gltf
