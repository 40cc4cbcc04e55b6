// Writing .gibake bake files (format: io/loader/include/gibake/format.h, docs/FORMAT.md).
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bake/ddgi_result.h"
#include "io/status.h"

namespace gibake {

struct BakeFileOptions {
  bool sh_float16 = false;     // SH coefficients as float16 instead of float32
  bool atlas_float16 = true;   // atlases as RGBA16F / RG16F instead of 32-bit
  // Optional: told when float16 conversion clamps values above 65504.
  std::function<void(const std::string&)> warn;
};

struct BakeOutputs {
  const DdgiResult* ddgi = nullptr;  // optional section group
  std::string metadata_json;          // settings, tool version, timings
  uint64_t input_hash = 0;            // hash_inputs() of the scene files and settings
};

// Hash of the scene files' bytes (scene, buffers, images), the bake settings and the gibake
// version, for staleness checks. XXH3-64. `settings` is canonicalised first when it parses as JSON
// (keys sorted, compact), so the bake command and `gibake verify --scene` (which re-hashes the
// metadata's "settings" object) agree however the JSON was spaced.
Status hash_inputs(const std::vector<std::string>& files, const std::string& settings,
                   uint64_t& out);

// Atomic write: temporary file in the target folder, fsync, rename, fsync folder. Refuses to
// overwrite any of `inputs` (same device and inode). The previous file survives any failure.
Status write_bake_file(const std::string& path, const BakeOutputs& outputs,
                       const BakeFileOptions& options, const std::vector<std::string>& inputs);

// The bytes write_bake_file would write (no file I/O); for tests, fuzz corpora and tools.
Status build_bake_file(const BakeOutputs& outputs, const BakeFileOptions& options,
                       std::vector<uint8_t>& out);

// The gibake version baked into hashes and metadata.
const char* gibake_version_string();

}  // namespace gibake
