// Morph targets and skins at rest (gltf_deform.h).
#include "io/gltf/gltf_deform.h"

#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "io/gltf/accessor_read.h"
#include "io/gltf/gltf_nodes.h"
#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {
namespace {

// Reads a target's attribute `name` (VEC3) into `out`, empty when the target has none.
Status read_target(const ImportEnv& env, const std::string& where, const std::map<std::string, int>& target,
                   const char* name, size_t vertices, std::vector<float>& out) {
  out.clear();
  auto it = target.find(name);
  if (it == target.end()) return Status::ok();
  int comps = 0;
  GIBAKE_TRY(read_float_accessor(env, it->second, {TINYGLTF_TYPE_VEC3}, out, comps));
  if (out.size() != 3 * vertices) return env.invalid(where, std::string(name) + " count differs from POSITION count");
  for (float f : out)
    if (!std::isfinite(f)) return env.invalid(where, std::string(name) + " contains NaN or infinity");
  return Status::ok();
}

// Reads WEIGHTS_n or JOINTS_n for every set n into `out`, 4 values a vertex a set, sets side by side.
Status read_sets(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p, const char* prefix,
                 size_t vertices, int sets, std::vector<float>& out) {
  out.assign(vertices * 4 * size_t(sets), 0.f);
  for (int s = 0; s < sets; ++s) {
    const std::string name = prefix + std::to_string(s);
    std::vector<float> v;
    int comps = 0;
    GIBAKE_TRY(read_float_accessor(env, p.attributes.at(name), {TINYGLTF_TYPE_VEC4}, v, comps));
    if (v.size() != 4 * vertices) return env.invalid(where, name + " count differs from POSITION count");
    for (size_t i = 0; i < vertices; ++i)
      for (size_t c = 0; c < 4; ++c) out[i * 4 * size_t(sets) + 4 * size_t(s) + c] = v[4 * i + c];
  }
  return Status::ok();
}

Mat4 accessor_matrix(const std::vector<float>& m, size_t j) {
  Mat4 out{};
  for (size_t k = 0; k < 16; ++k) out[k] = m[16 * j + k];
  return out;
}

// Each joint's matrix: world(joint) x inverseBindMatrix (identity when the skin gives none).
Status joint_matrices(const ImportEnv& env, int skin, const std::vector<Mat4>& worlds, std::vector<Mat4>& out) {
  const auto& m = *env.model;
  const std::string where = at("skins", size_t(skin));
  const tinygltf::Skin& s = m.skins[size_t(skin)];
  if (s.joints.empty()) return env.invalid(where, "skin has no joints");
  std::vector<float> ibm;
  if (s.inverseBindMatrices >= 0) {
    int comps = 0;
    GIBAKE_TRY(read_float_accessor(env, s.inverseBindMatrices, {TINYGLTF_TYPE_MAT4}, ibm, comps));
    if (ibm.size() < 16 * s.joints.size())
      return env.invalid(where, "inverseBindMatrices holds fewer matrices than the skin's joints");
  }
  out.clear();
  for (size_t j = 0; j < s.joints.size(); ++j) {
    const int node = s.joints[j];
    if (node < 0 || size_t(node) >= worlds.size())
      return env.invalid(where + ".joints[" + std::to_string(j) + "]", "node index out of range");
    out.push_back(ibm.empty() ? worlds[size_t(node)] : mat_mul(worlds[size_t(node)], accessor_matrix(ibm, j)));
  }
  return Status::ok();
}

// The blend of one vertex's joints: sum of weight x joint matrix over its influences, the weights
// scaled to sum to 1 (glTF requires that sum; exporters round it). False when every weight is 0.
bool blend_of(const PrimitiveData& d, size_t v, const std::vector<Mat4>& joints, Mat4& out, bool& bad_joint) {
  const size_t n = size_t(d.influences);
  double total = 0.0;
  for (size_t k = 0; k < n; ++k) total += std::fabs(double(d.joint_weights[v * n + k]));
  if (!(total > 0.0)) return false;
  out = Mat4{};
  for (size_t k = 0; k < n; ++k) {
    const double w = double(d.joint_weights[v * n + k]) / total;
    if (w == 0.0) continue;
    const double j = double(d.joints[v * n + k]);
    if (!(j >= 0.0) || j >= double(joints.size())) {
      bad_joint = true;
      return false;
    }
    const Mat4& m = joints[size_t(j)];
    for (size_t e = 0; e < 16; ++e) out[e] += w * m[e];
  }
  return true;
}

void move_point(const Mat4& m, const float* p, float* out) {
  for (size_t r = 0; r < 3; ++r) out[r] = to_float(m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
}

void move_normal(const Mat4& m, const float* n, float* out) {
  std::array<double, 9> nm{};
  double v[3] = {n[0], n[1], n[2]};
  if (mat_normal_matrix(m, nm))
    for (size_t r = 0; r < 3; ++r) v[r] = nm[r * 3] * n[0] + nm[r * 3 + 1] * n[1] + nm[r * 3 + 2] * n[2];
  const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  const bool ok = l > 1e-30 && std::isfinite(l);
  for (size_t r = 0; r < 3; ++r) out[r] = ok ? float(v[r] / l) : (r == 2 ? 1.f : 0.f);
}

}  // namespace

std::vector<double> morph_weights(const tinygltf::Node& node, const tinygltf::Mesh& mesh) {
  return node.weights.empty() ? mesh.weights : node.weights;
}

Status apply_morph_targets(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                           const std::vector<double>& weights, PrimitiveData& d) {
  const size_t n = d.vertex_count();
  std::vector<float> delta;
  for (size_t t = 0; t < p.targets.size() && t < weights.size(); ++t) {
    const double w = weights[t];
    if (w == 0.0) continue;
    const std::string target_at = where + ".targets[" + std::to_string(t) + "]";
    GIBAKE_TRY(read_target(env, target_at, p.targets[t], "POSITION", n, delta));
    for (size_t i = 0; i < delta.size(); ++i) d.positions[i] = to_float(double(d.positions[i]) + w * delta[i]);
    GIBAKE_TRY(read_target(env, target_at, p.targets[t], "NORMAL", n, delta));
    if (d.normals.size() == delta.size())
      for (size_t i = 0; i < delta.size(); ++i) d.normals[i] = to_float(double(d.normals[i]) + w * delta[i]);
  }
  for (float f : d.positions)
    if (!std::isfinite(f)) return env.invalid(where, "POSITION with its morph targets is not finite");
  return Status::ok();
}

Status read_skin_attributes(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                            PrimitiveData& d) {
  int sets = 0;
  while (p.attributes.count("JOINTS_" + std::to_string(sets)) && p.attributes.count("WEIGHTS_" + std::to_string(sets)))
    ++sets;
  if (sets == 0) return Status::ok();
  GIBAKE_TRY(read_sets(env, where, p, "JOINTS_", d.vertex_count(), sets, d.joints));
  GIBAKE_TRY(read_sets(env, where, p, "WEIGHTS_", d.vertex_count(), sets, d.joint_weights));
  d.influences = 4 * sets;
  return Status::ok();
}

Status node_world_matrices(const ImportEnv& env, std::vector<Mat4>& out) {
  // collect_scene_nodes has refused cycles: every chain ends at a root.
  const auto& nodes = env.model->nodes;
  std::vector<int> parent;
  GIBAKE_TRY(build_parents(env, parent));
  out.assign(nodes.size(), Mat4{});
  std::vector<char> done(nodes.size(), 0);
  std::vector<size_t> chain;
  for (size_t i = 0; i < nodes.size(); ++i) {
    chain.clear();
    for (int k = int(i); k >= 0 && !done[size_t(k)]; k = parent[size_t(k)]) chain.push_back(size_t(k));
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      Mat4 local;
      GIBAKE_TRY(node_local_matrix(env, *it, local));
      out[*it] = parent[*it] >= 0 ? mat_mul(out[size_t(parent[*it])], local) : local;
      done[*it] = 1;
    }
  }
  return Status::ok();
}

Status skin_primitive(const ImportEnv& env, const std::string& where, int skin, const std::vector<Mat4>& worlds,
                      const PrimitiveData& local, PrimitiveData& out) {
  std::vector<Mat4> joints;
  GIBAKE_TRY(joint_matrices(env, skin, worlds, joints));
  out = local;
  const size_t n = local.vertex_count();
  std::vector<double> det(n, 1.0);
  size_t unweighted = 0;
  for (size_t v = 0; v < n; ++v) {
    Mat4 b{};
    bool bad_joint = false;
    if (!blend_of(local, v, joints, b, bad_joint)) {
      if (bad_joint) return env.invalid(where, "a JOINTS value lies beyond the skin's joints");
      b = joints[0];  // no weight at all: the first joint carries it
      ++unweighted;
    }
    move_point(b, &local.positions[3 * v], &out.positions[3 * v]);
    move_normal(b, &local.normals[3 * v], &out.normals[3 * v]);
    det[v] = mat_det3(b);
  }
  for (size_t t = 0; t + 2 < out.indices.size(); t += 3)
    if (det[out.indices[t]] < 0.0) std::swap(out.indices[t + 1], out.indices[t + 2]);
  if (unweighted > 0)
    env.ctx->warning(env.file + ": " + where + ": " + std::to_string(unweighted) +
                     " vertices have no joint weight; moved by the skin's first joint");
  return Status::ok();
}

}  // namespace gibake::gltf
