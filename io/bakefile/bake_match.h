// Whether a bake file was made from a scene as it is now. A bake that recorded its inputs' digest
// (metadata "inputs", input_digest.h) is matched by content: the scene's geometry, materials,
// textures and lights as imported, the bake's own recorded settings and the gibake version, against
// the file header's input hash; what changed is named by part and by file. A bake from before
// content hashing is matched by the hash of its scene files' bytes (hash_inputs), as it was made.
// A preview of one scene with another scene's bake would otherwise render without a word.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "io/bakefile/input_digest.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct BakeSceneMatch {
  bool matches = false;
  bool by_content = false;  // the bake recorded its digest; else its hash is of the files' bytes
  uint64_t bake_hash = 0, scene_hash = 0;
  InputChanges changes;     // by_content: what differs from the recorded digest
  std::string baked_version, version;  // the gibake that baked the file, this one
  // One phrase for people: what changed (empty when the bake matches and no file was re-saved).
  std::string what() const;
};

// IoFailure when a scene file cannot be read for hashing.
Status match_bake_to_scene(const loader::BakeFile& file, const Scene& scene, BakeSceneMatch& out);

}  // namespace gibake
