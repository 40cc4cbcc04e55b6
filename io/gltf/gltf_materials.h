// Materials, textures (already decoded by gltf_load) and samplers into Scene.
#pragma once
#include "io/gltf/gltf_internal.h"
#include "io/gltf/gltf_tiny.h"
#include "io/scene.h"

namespace gibake::gltf {

// Fills scene.textures (one per glTF texture, in order) and scene.materials (one per material).
// `images` are the model's decoded images; their pixels are moved into the scene.
Status import_materials(const ImportEnv& env, std::vector<tinygltf::Image>& images, Scene& scene);

// Lenient reads of extension values (numbers that do not fit come back as `fallback`).
double value_number(const tinygltf::Value& v, double fallback);

}  // namespace gibake::gltf
