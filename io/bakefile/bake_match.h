// Whether a bake file was made from a scene: the input hash recomputed from the scene's files (as
// the importer read them) and the bake's own recorded settings, against the file header's. A
// preview of one scene with another scene's bake would otherwise render without a word.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/status.h"

namespace gibake {

struct BakeSceneMatch {
  bool matches = false;
  uint64_t bake_hash = 0, scene_hash = 0;
};

// IoFailure when a scene file cannot be read for hashing.
Status match_bake_to_scene(const loader::BakeFile& file, const std::vector<std::string>& scene_files,
                           BakeSceneMatch& out);

// "0x0123456789abcdef"
std::string hash_text(uint64_t hash);

}  // namespace gibake
