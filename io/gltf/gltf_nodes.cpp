// Node graph validation and transforms.
#include "io/gltf/gltf_nodes.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {

std::string at(const char* name, size_t i) { return std::string(name) + "[" + std::to_string(i) + "]"; }
std::string at(const char* name, size_t i, const char* sub, size_t j) {
  return at(name, i) + "." + at(sub, j);
}

Status ImportEnv::check_coordinates(const std::string& where, const char* what, const float p[3]) const {
  const double limit = limits().max_coordinate;
  if (std::fabs(p[0]) <= limit && std::fabs(p[1]) <= limit && std::fabs(p[2]) <= limit) return Status::ok();
  char text[160];
  std::snprintf(text, sizeof text, "%s (%g, %g, %g) m lies beyond %g m of the origin, outside the ray tracer's range",
                what, double(p[0]), double(p[1]), double(p[2]), limit);
  return invalid(where, text);
}

float to_float(double v) {
  if (std::isnan(v)) return std::numeric_limits<float>::quiet_NaN();
  if (v > double(std::numeric_limits<float>::max())) return std::numeric_limits<float>::infinity();
  if (v < -double(std::numeric_limits<float>::max())) return -std::numeric_limits<float>::infinity();
  return float(v);
}

Mat4 mat_identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 mat_mul(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[size_t(k * 4 + row)] * b[size_t(c * 4 + k)];
      r[size_t(c * 4 + row)] = s;
    }
  return r;
}

// Element (row, col) of the upper 3x3 of a column-major matrix.
static double e(const Mat4& m, int row, int col) { return m[size_t(col * 4 + row)]; }

double mat_det3(const Mat4& m) {
  return e(m, 0, 0) * (e(m, 1, 1) * e(m, 2, 2) - e(m, 1, 2) * e(m, 2, 1)) -
         e(m, 0, 1) * (e(m, 1, 0) * e(m, 2, 2) - e(m, 1, 2) * e(m, 2, 0)) +
         e(m, 0, 2) * (e(m, 1, 0) * e(m, 2, 1) - e(m, 1, 1) * e(m, 2, 0));
}

bool mat_normal_matrix(const Mat4& m, std::array<double, 9>& out) {
  double det = mat_det3(m);
  if (!std::isfinite(det) || det == 0.0) return false;
  // inverse transpose = cofactor matrix / det (row-major out[r*3+c]).
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      double cof = e(m, r1, c1) * e(m, r2, c2) - e(m, r1, c2) * e(m, r2, c1);
      out[size_t(r * 3 + c)] = cof / det;
    }
  return true;
}

namespace {

bool all_finite(const std::vector<double>& v) {
  for (double d : v)
    if (!std::isfinite(d)) return false;
  return true;
}

}  // namespace

Status node_local_matrix(const ImportEnv& env, size_t i, Mat4& out) {
  const auto& n = env.model->nodes[i];
  std::string where = at("nodes", i);
  if (!all_finite(n.matrix) || !all_finite(n.translation) || !all_finite(n.rotation) || !all_finite(n.scale))
    return env.invalid(where, "transform contains NaN or infinity");
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16) return env.invalid(where, "matrix must have 16 numbers");
    for (size_t k = 0; k < 16; ++k) out[k] = n.matrix[k];
    return Status::ok();
  }
  if ((!n.translation.empty() && n.translation.size() != 3) || (!n.scale.empty() && n.scale.size() != 3) ||
      (!n.rotation.empty() && n.rotation.size() != 4))
    return env.invalid(where, "translation/rotation/scale have the wrong number of elements");
  double t[3] = {0, 0, 0}, s[3] = {1, 1, 1}, q[4] = {0, 0, 0, 1};
  for (size_t k = 0; k < n.translation.size(); ++k) t[k] = n.translation[k];
  for (size_t k = 0; k < n.scale.size(); ++k) s[k] = n.scale[k];
  for (size_t k = 0; k < n.rotation.size(); ++k) q[k] = n.rotation[k];
  double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(len > 1e-12) || !std::isfinite(len)) return env.invalid(where, "rotation quaternion has zero length");
  double x = q[0] / len, y = q[1] / len, z = q[2] / len, w = q[3] / len;
  double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                 2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                 2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
  out = mat_identity();
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) out[size_t(c * 4 + r)] = R[r * 3 + c] * s[c];
  for (int r = 0; r < 3; ++r) out[size_t(12 + r)] = t[r];
  return Status::ok();
}

Status build_parents(const ImportEnv& env, std::vector<int>& parent) {
  const auto& nodes = env.model->nodes;
  parent.assign(nodes.size(), -1);
  for (size_t i = 0; i < nodes.size(); ++i)
    for (int c : nodes[i].children) {
      if (c < 0 || size_t(c) >= nodes.size())
        return env.invalid(at("nodes", i), "child index " + std::to_string(c) + " out of range");
      if (size_t(c) == i) return env.invalid(at("nodes", i), "node is its own child (cycle)");
      if (parent[size_t(c)] >= 0)
        return env.invalid(at("nodes", size_t(c)), "node has two parents (nodes " +
                                                       std::to_string(parent[size_t(c)]) + " and " +
                                                       std::to_string(i) + ")");
      parent[size_t(c)] = int(i);
    }
  return Status::ok();
}

namespace {

// Every parent chain must end at a root: refuses cycles even where no scene reaches them.
Status check_acyclic(const ImportEnv& env, const std::vector<int>& parent) {
  std::vector<char> state(parent.size(), 0);  // 0 unknown, 1 on the current walk, 2 ends at a root
  std::vector<size_t> walk;
  for (size_t i = 0; i < parent.size(); ++i) {
    walk.clear();
    size_t k = i;
    while (state[k] == 0) {
      state[k] = 1;
      walk.push_back(k);
      if (parent[k] < 0) break;
      k = size_t(parent[k]);
    }
    if (state[k] == 1 && parent[k] >= 0)
      return env.invalid(at("nodes", k), "node hierarchy contains a cycle");
    for (size_t w : walk) state[w] = 2;
  }
  return Status::ok();
}

Status scene_roots(const ImportEnv& env, const std::vector<int>& parent, std::vector<int>& roots) {
  const auto& m = *env.model;
  roots.clear();
  if (m.scenes.empty()) {
    for (size_t i = 0; i < parent.size(); ++i)
      if (parent[i] < 0) roots.push_back(int(i));
    if (!m.nodes.empty()) env.ctx->warning(env.file + ": no scenes; using all root nodes");
    return Status::ok();
  }
  int s = m.defaultScene;
  if (s >= int(m.scenes.size())) return env.invalid("scene", "default scene index out of range");
  if (s < 0) s = 0;
  for (int r : m.scenes[size_t(s)].nodes) {
    if (r < 0 || size_t(r) >= m.nodes.size())
      return env.invalid(at("scenes", size_t(s)), "node index " + std::to_string(r) + " out of range");
    if (parent[size_t(r)] >= 0)
      return env.invalid(at("scenes", size_t(s)), "root node " + std::to_string(r) + " has a parent");
    roots.push_back(r);
  }
  return Status::ok();
}

}  // namespace

Status collect_scene_nodes(const ImportEnv& env, std::vector<NodeInstance>& out) {
  const auto& nodes = env.model->nodes;
  std::vector<int> parent, roots;
  GIBAKE_TRY(build_parents(env, parent));
  GIBAKE_TRY(check_acyclic(env, parent));
  GIBAKE_TRY(scene_roots(env, parent, roots));
  std::vector<char> visited(nodes.size(), 0);
  std::vector<NodeInstance> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, mat_identity()});
  out.clear();
  while (!stack.empty()) {
    NodeInstance ni = stack.back();
    stack.pop_back();
    size_t i = size_t(ni.node);
    if (visited[i]) return env.invalid(at("nodes", i), "node hierarchy contains a cycle or repeats a root");
    visited[i] = 1;
    Mat4 local;
    GIBAKE_TRY(node_local_matrix(env, i, local));
    ni.world = mat_mul(ni.world, local);
    out.push_back(ni);
    const auto& ch = nodes[i].children;
    for (auto c = ch.rbegin(); c != ch.rend(); ++c) stack.push_back({*c, ni.world});
  }
  return Status::ok();
}

}  // namespace gibake::gltf
