// Checks before tinygltf reads a file: a .glb without the GLB magic is named as such (not "not
// valid JSON"), and a type check of the glTF JSON. tinygltf quietly skips a property of the
// wrong type (a material given as an array, a texture index of -1, a name that is a number), so a
// file bakes differently from what its author meant without a word. Here each such property is
// named with its place: a property the spec requires (meshes[i].primitives, accessors[i].count …)
// is an error, any other a warning that it was ignored.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/context.h"
#include "io/status.h"

namespace gibake::gltf {

// Whether `path` ends in .glb (any case), and the message for one without the magic (which says
// when the bytes are a PNG or JPEG image, or glTF JSON).
bool named_glb(const std::string& path);
std::string not_glb_text(const std::vector<unsigned char>& bytes);

// InvalidInput naming the first required property of the wrong type; warnings (through ctx, at
// most a screenful, then a count) for the optional ones.
Status check_json_types(const std::string& file, const nlohmann::json& doc, const Context& ctx);

}  // namespace gibake::gltf
