// The files an import would read, from a cheap pre-read of the scene's JSON (a .glb's JSON chunk
// only): the scene itself, then every external buffer and image. Commands check their outputs
// against this list before the import starts; the import's own list (Scene::input_files) stays the
// authority for hashes and depfiles.
#pragma once
#include <string>
#include <vector>

#include "io/output/output_check.h"
#include "io/status.h"

namespace gibake {

// Never fails: what cannot be read or parsed is left out (the import then reports it properly).
// Roles are "scene", "buffers[i]" and "images[i]".
std::vector<NamedPath> scene_input_files(const std::string& scene_path);

// A gibake bake file given where a scene goes (`gibake probes.gibake --ddgi`): an InvalidInput
// Status naming it as one, so that it is not parsed as glTF JSON. Ok for anything else, unreadable
// files included (the import reports those).
Status refuse_bake_file_as_scene(const std::string& scene_path);

}  // namespace gibake
