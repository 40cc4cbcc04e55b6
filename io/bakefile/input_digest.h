// What a bake was made from, hashed by what the bakers read of the scene (its geometry, materials,
// textures and lights as imported), not by the bytes of its files: a .gltf re-saved with the same
// content is the same input. Each part is hashed on its own so that staleness can say what changed,
// and each file's bytes are hashed too so that it can say which file. The bake records the digest
// in its metadata ("inputs") and the header's input_hash is content_input_hash() of it.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct InputDigest {
  // The metadata's "inputs"."scheme"; a file without it was hashed by file bytes (hash_inputs).
  static constexpr const char* kScheme = "content-1";
  uint64_t geometry = 0, materials = 0, textures = 0, lights = 0;
  struct File {
    std::string path;  // relative to the scene file's folder ('/' separated)
    std::string kind;  // "scene", "buffer" or "image"
    uint64_t bytes = 0;
  };
  std::vector<File> files;  // the import's input_files, in order
};

// The content parts of an imported scene (no file I/O).
InputDigest digest_scene(const Scene& scene);
// The byte hashes of the scene's input_files into `digest.files` (IoFailure when one cannot be read).
Status digest_files(const std::vector<std::string>& input_files, InputDigest& digest);
// The header's input hash: the parts, the canonical settings (as hash_inputs canonicalises them)
// and the gibake version.
// A 64-bit hash as the files and messages write it: 0x and 16 hex digits.
std::string hash_text(uint64_t hash);

uint64_t content_input_hash(const InputDigest& digest, const std::string& settings,
                            const std::string& version);

nlohmann::json input_digest_json(const InputDigest& digest);
// False when `j` is not a digest of kScheme (a file baked before content hashing, or a later scheme).
bool input_digest_from_json(const nlohmann::json& j, InputDigest& out);

// How the scene as it is now stands against the bake's recorded digest: the parts that changed
// ("geometry", "materials", "textures", "lights"), files whose bytes changed, appeared or went.
struct InputChanges {
  std::vector<std::string> parts;
  std::vector<std::string> files_changed, files_added, files_removed;  // "path (kind)"
};
InputChanges compare_digests(const InputDigest& baked, const InputDigest& now);

}  // namespace gibake
