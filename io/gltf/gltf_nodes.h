// The node hierarchy: scene roots, graph checks (cycles, two parents), world matrices.
#pragma once
#include <vector>

#include "io/gltf/gltf_internal.h"

namespace gibake::gltf {

struct NodeInstance {
  int node = -1;
  Mat4 world{};
};

// Node i's local matrix (its matrix, or translation x rotation x scale); refuses non-finite or
// malformed transforms.
Status node_local_matrix(const ImportEnv& env, size_t i, Mat4& out);

// parent[i] for every node (-1 for a root); refuses bad child indices, self-children and second
// parents.
Status build_parents(const ImportEnv& env, std::vector<int>& parent);

// Every node reachable from the scene's roots (default scene, else the first, else all
// parentless nodes), each with its world matrix, parents before children.
Status collect_scene_nodes(const ImportEnv& env, std::vector<NodeInstance>& out);

}  // namespace gibake::gltf
