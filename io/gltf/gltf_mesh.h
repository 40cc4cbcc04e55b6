// One mesh primitive into local-space triangles: attributes, modes, generated normals.
#pragma once
#include "io/gltf/gltf_internal.h"

namespace gibake::gltf {

// Decodes meshes[mesh].primitives[prim] (plain accessors or KHR_draco_mesh_compression), its morph
// targets at `weights` (gltf_deform.h). POINTS/LINES come back with `skipped` set (and a warning);
// errors are InvalidInput.
Status decode_primitive(const ImportEnv& env, size_t mesh, size_t prim, const std::vector<double>& weights,
                        PrimitiveData& out);

// Turns a glTF index list of `mode` into a triangle list (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN).
std::vector<uint32_t> triangulate(int mode, const std::vector<uint32_t>& idx);

// Fills out.normals: area-weighted over shared vertices when `smooth`, else flat (every triangle
// its own vertices, as glTF requires of a primitive without NORMAL).
void generate_normals(PrimitiveData& out, bool smooth);

}  // namespace gibake::gltf
