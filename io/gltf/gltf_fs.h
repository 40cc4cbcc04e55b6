// File access for tinygltf: every external URI must resolve inside the scene's folder, no scheme
// but data:, with size caps. Used through tinygltf::FsCallbacks (see gltf_load.cpp).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/gltf/import.h"
#include "io/status.h"

namespace gibake::gltf {

struct FsState {
  std::string base_dir;       // canonical absolute folder of the scene file, no trailing '/'
  std::string user_file;      // the path the user gave (error `file`)
  const ImportLimits* limits = nullptr;
  uint64_t total_bytes = 0;   // external files read so far (buffers and images)
  std::vector<std::string> files_read;
  std::vector<std::string> files_missing;  // image files named inside the folder that do not exist
  Status error;               // first refusal; wins over tinygltf's own message
};

// Percent-decoding as tinygltf applies it before opening a file ('+' is a space).
std::string uri_decode(const std::string& uri);

// True for the base64 data: URIs tinygltf decodes itself.
bool is_supported_data_uri(const std::string& uri);

// Checks a decoded relative URI; on success `resolved` is base_dir + "/" + normalised path.
// Refuses schemes (file:, http:, C:), absolute paths, UNC paths, backslashes, NUL bytes and
// `..` that leaves the folder. `what` receives the reason.
bool resolve_relative(const std::string& base_dir, const std::string& decoded, std::string& resolved,
                      std::string& what);

// Reads a whole file with the size cap; IoFailure when it cannot be read, InvalidInput when it is
// too large.
Status read_file_capped(const std::string& path, uint64_t max_bytes, const std::string& where,
                        std::vector<unsigned char>& out);

// tinygltf FsCallbacks functions; user_data is an FsState*.
bool fs_file_exists(const std::string& abs_filename, void* user_data);
std::string fs_expand_file_path(const std::string& path, void* user_data);
bool fs_read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                        void* user_data);
bool fs_write_whole_file(std::string* err, const std::string& path,
                         const std::vector<unsigned char>& contents, void* user_data);

}  // namespace gibake::gltf
