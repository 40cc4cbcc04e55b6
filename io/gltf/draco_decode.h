// KHR_draco_mesh_compression decoded by gibake (not tinygltf): every index, range and count is
// checked before the decoded data is used.
#pragma once
#include "io/gltf/gltf_internal.h"

namespace gibake::gltf {

// Fills positions, indices and, when the stream has them, normals, uvs and colors (rgba).
Status decode_draco_primitive(const ImportEnv& env, size_t mesh, size_t prim, PrimitiveData& out);

}  // namespace gibake::gltf
