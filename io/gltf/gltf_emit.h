// Internal: placing decoded primitives into the Scene (implemented in import_emit.cpp).
#pragma once
#include "io/gltf/gltf_internal.h"
#include "io/gltf/gltf_nodes.h"
#include "io/scene.h"

namespace gibake::gltf {

// Appends `d` transformed by the node's world matrix; flips winding for negative determinants.
// Scene::colors is always filled here (white where absent); the caller clears it if unused.
Status emit_instance(const ImportEnv& env, const NodeInstance& ni, size_t mesh, size_t prim,
                     const PrimitiveData& d, Scene& scene);

}  // namespace gibake::gltf
