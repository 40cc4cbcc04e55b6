// KHR_lights_punctual: lights placed by scene nodes, in world space.
#pragma once
#include <vector>

#include "io/gltf/gltf_internal.h"
#include "io/gltf/gltf_nodes.h"
#include "io/scene.h"

namespace gibake::gltf {

Status import_lights(const ImportEnv& env, const std::vector<NodeInstance>& nodes, Scene& scene);

}  // namespace gibake::gltf
