// The rest pose a static bake sees: morph targets at their default weights and skinned meshes at
// the pose their joints' node transforms give (glTF 2.0 3.7.2.2 and 3.7.3). Animations are not
// played: the nodes' own transforms are the pose.
#pragma once
#include <vector>

#include "io/gltf/gltf_internal.h"
#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {

// The morph weights a node shows: node.weights when given, else its mesh's weights, else none
// (every target at weight 0).
std::vector<double> morph_weights(const tinygltf::Node& node, const tinygltf::Mesh& mesh);

// Adds sum_i weights[i] x targets[i] to a plain primitive's POSITION and NORMAL (read before its
// normals are generated, so that generated normals follow the morphed shape). Weights beyond the
// primitive's targets, or targets beyond the weights, count as 0.
Status apply_morph_targets(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                           const std::vector<double>& weights, PrimitiveData& d);

// Reads JOINTS_n / WEIGHTS_n of a plain primitive into d.joints / d.joint_weights.
Status read_skin_attributes(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                            PrimitiveData& d);

// Every node's world matrix (parents' first), for the joints of skins.
Status node_world_matrices(const ImportEnv& env, std::vector<Mat4>& out);

// The skinned primitive in world space: each vertex moved by its joints' matrices
// (world(joint) x inverseBindMatrix) blended by its weights, normals by the blend's inverse
// transpose, and a triangle whose blend mirrors it turned to keep its front. The mesh node's own
// transform is not applied, as glTF requires.
Status skin_primitive(const ImportEnv& env, const std::string& where, int skin, const std::vector<Mat4>& worlds,
                      const PrimitiveData& local, PrimitiveData& out);

}  // namespace gibake::gltf
