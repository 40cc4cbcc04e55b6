// Confined, capped file access for the glTF importer.
#include "io/gltf/gltf_fs.h"

#include <sys/stat.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

namespace gibake::gltf {
namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool has_scheme(const std::string& s) {
  size_t colon = s.find(':');
  if (colon == std::string::npos) return false;
  size_t slash = s.find('/');
  return slash == std::string::npos || colon < slash;
}

// Lexically normalises a relative path; false when `..` climbs above the start.
bool normalise(const std::string& rel, std::string& out) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (start <= rel.size()) {
    size_t end = rel.find('/', start);
    if (end == std::string::npos) end = rel.size();
    std::string seg = rel.substr(start, end - start);
    if (seg == "..") {
      if (parts.empty()) return false;
      parts.pop_back();
    } else if (!seg.empty() && seg != ".") {
      parts.push_back(seg);
    }
    start = end + 1;
  }
  out.clear();
  for (const auto& p : parts) out += (out.empty() ? "" : "/") + p;
  return true;
}

// Canonical path when the file exists; empty otherwise.
std::string canonical(const std::string& path) {
  std::unique_ptr<char, decltype(&std::free)> r(realpath(path.c_str(), nullptr), &std::free);
  return r ? std::string(r.get()) : std::string();
}

bool inside(const std::string& base, const std::string& path) {
  return path.size() > base.size() + 1 && path.compare(0, base.size(), base) == 0 &&
         path[base.size()] == '/';
}

}  // namespace

std::string uri_decode(const std::string& uri) {
  std::string out;
  out.reserve(uri.size());
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%' && i + 2 < uri.size() && hex_value(uri[i + 1]) >= 0 &&
               hex_value(uri[i + 2]) >= 0) {
      out += static_cast<char>(hex_value(uri[i + 1]) * 16 + hex_value(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

bool is_supported_data_uri(const std::string& uri) {
  static const char* kHeaders[] = {
      "data:application/octet-stream;base64,", "data:image/jpeg;base64,",
      "data:image/png;base64,",                "data:image/bmp;base64,",
      "data:image/gif;base64,",                "data:text/plain;base64,",
      "data:application/gltf-buffer;base64,"};
  for (const char* h : kHeaders)
    if (uri.compare(0, std::char_traits<char>::length(h), h) == 0) return true;
  return false;
}

bool resolve_relative(const std::string& base_dir, const std::string& decoded, std::string& resolved,
                      std::string& what) {
  if (decoded.empty()) return what = "empty URI", false;
  if (decoded.find('\0') != std::string::npos) return what = "URI contains a NUL byte", false;
  if (decoded.find('\\') != std::string::npos)
    return what = "URI contains a backslash (not a portable relative path)", false;
  if (decoded[0] == '/') return what = "absolute path URI is not allowed", false;
  if (has_scheme(decoded))
    return what = "URI scheme or drive letter is not allowed (only data: and relative paths)", false;
  std::string norm;
  if (!normalise(decoded, norm)) return what = "URI escapes the scene folder", false;
  if (norm.empty()) return what = "URI names the scene folder itself, not a file", false;
  resolved = base_dir + "/" + norm;
  std::string real = canonical(resolved);
  if (!real.empty() && !inside(base_dir, real))
    return what = "URI resolves (through a link) outside the scene folder", false;
  return true;
}

Status read_file_capped(const std::string& path, uint64_t max_bytes, const std::string& where,
                        std::vector<unsigned char>& out) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return Status::io(path, std::string("cannot open file: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) return Status::io(path, "not a regular file");
  if (uint64_t(st.st_size) > max_bytes)
    return Status::invalid(path, where,
                           "file is " + std::to_string(st.st_size) + " bytes, over the limit of " +
                               std::to_string(max_bytes));
  std::unique_ptr<FILE, decltype(&std::fclose)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) return Status::io(path, std::string("cannot open file: ") + std::strerror(errno));
  out.resize(size_t(st.st_size));
  if (!out.empty() && std::fread(out.data(), 1, out.size(), f.get()) != out.size())
    return Status::io(path, "read failed");
  return Status::ok();
}

bool fs_file_exists(const std::string& abs_filename, void* user_data) {
  auto* fs = static_cast<FsState*>(user_data);
  if (!inside(fs->base_dir, abs_filename)) return false;  // e.g. tinygltf's "./" fallback
  struct stat st {};
  return ::stat(abs_filename.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string fs_expand_file_path(const std::string& path, void*) { return path; }

bool fs_read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                        void* user_data) {
  auto* fs = static_cast<FsState*>(user_data);
  std::string rel, resolved, what;
  if (inside(fs->base_dir, path)) rel = path.substr(fs->base_dir.size() + 1);
  if (rel.empty() || !resolve_relative(fs->base_dir, rel, resolved, what)) {
    if (fs->error.is_ok())
      fs->error = Status::invalid(fs->user_file, "uri", what.empty() ? "path outside the scene folder" : what);
    if (err) *err = "refused";
    return false;
  }
  uint64_t budget = fs->limits->max_total_buffer_bytes - std::min(fs->total_bytes, fs->limits->max_total_buffer_bytes);
  uint64_t cap = std::min<uint64_t>(fs->limits->max_file_bytes, budget);
  Status st = read_file_capped(resolved, cap, "", *out);
  if (!st.is_ok()) {
    if (fs->error.is_ok()) fs->error = st;
    if (err) *err = st.what();
    return false;
  }
  fs->total_bytes += out->size();
  fs->files_read.push_back(resolved);
  return true;
}

bool fs_write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&,
                         void*) {
  if (err) *err = "writing is disabled";
  return false;
}

}  // namespace gibake::gltf
