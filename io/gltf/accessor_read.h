// Validated reads of glTF accessors: every range is overflow-checked against its bufferView and
// buffer before a byte is touched; sparse substitution included.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/gltf/gltf_internal.h"
#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {

// Components per element for a TINYGLTF_TYPE_* (0 when unknown).
int type_components(int type);
// Bytes per component for a TINYGLTF_COMPONENT_TYPE_* (0 when unknown).
int component_bytes(int component_type);

// Reads accessor `index` as floats (normalized integers mapped per the glTF spec, others
// converted), `components` per element; `out` gets count*components values.
// `allowed_types` lists acceptable TINYGLTF_TYPE_* values.
Status read_float_accessor(const ImportEnv& env, int index, const std::vector<int>& allowed_types,
                           std::vector<float>& out, int& components);

// Reads an index accessor (SCALAR, unsigned byte/short/int, not normalized).
Status read_index_accessor(const ImportEnv& env, int index, std::vector<uint32_t>& out);

// The accessor's element count after validating the index (for Draco, whose data is elsewhere).
Status accessor_count(const ImportEnv& env, int index, size_t& count);

}  // namespace gibake::gltf
