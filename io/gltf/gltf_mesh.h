// One mesh primitive into local-space triangles: attributes, modes, generated normals.
#pragma once
#include "io/gltf/gltf_internal.h"

namespace gibake::gltf {

// Decodes meshes[mesh].primitives[prim] (plain accessors or KHR_draco_mesh_compression).
// POINTS/LINES come back with `skipped` set (and a warning); errors are InvalidInput.
Status decode_primitive(const ImportEnv& env, size_t mesh, size_t prim, PrimitiveData& out);

// Turns a glTF index list of `mode` into a triangle list (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN).
std::vector<uint32_t> triangulate(int mode, const std::vector<uint32_t>& idx);

// Fills out.normals: area-weighted smooth when `indexed`, else flat (vertices un-shared).
void generate_normals(PrimitiveData& out, bool indexed);

}  // namespace gibake::gltf
