// Internal types shared by the glTF importer's translation units (not part of the public API).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/context.h"
#include "io/gltf/import.h"
#include "io/status.h"

namespace tinygltf {
class Model;
struct Primitive;
}

namespace gibake::gltf {

// What every stage needs to report errors and honour limits.
struct ImportEnv {
  std::string file;  // the path the user gave: the `file` of errors
  const ImportOptions* options = nullptr;
  const Context* ctx = nullptr;
  const tinygltf::Model* model = nullptr;

  Status invalid(const std::string& where, const std::string& what) const {
    return Status::invalid(file, where, what);
  }
  const ImportLimits& limits() const { return options->limits; }
  // InvalidInput when a coordinate of `p` lies beyond ImportLimits::max_coordinate.
  Status check_coordinates(const std::string& where, const char* what, const float p[3]) const;
};

// "name[i]" and "name[i].sub[j]".
std::string at(const char* name, size_t i);
std::string at(const char* name, size_t i, const char* sub, size_t j);

// A primitive decoded into local (mesh) space, triangles only.
struct PrimitiveData {
  std::vector<float> positions;  // xyz
  std::vector<float> normals;    // xyz, unit
  std::vector<float> uvs;        // uv, empty when absent
  std::vector<float> colors;     // rgba, empty when absent
  // Skinning: `influences` joints a vertex (4 per JOINTS_n set), their indices into the skin's
  // joints and their weights; empty when the primitive has none.
  std::vector<float> joints, joint_weights;
  int influences = 0;
  std::vector<uint32_t> indices;  // 3 per triangle, CCW in local space
  int material = -1;
  bool draco = false;
  bool skipped = false;  // POINTS/LINES or nothing to place
  size_t vertex_count() const { return positions.size() / 3; }
};

// The primitive's indices accessor, including one gltf_load.cpp moved to
// extensions.GIBAKE_indices because it has no bufferView; -1 when none.
int primitive_indices(const tinygltf::Primitive& p);

// Column-major 4x4 matrix in double, as glTF stores it.
using Mat4 = std::array<double, 16>;
Mat4 mat_identity();
Mat4 mat_mul(const Mat4& a, const Mat4& b);
double mat_det3(const Mat4& m);
// Inverse transpose of the upper 3x3 (row-major 3x3 result); false when singular.
bool mat_normal_matrix(const Mat4& m, std::array<double, 9>& out);

// Double -> float without undefined behaviour: out-of-range values become +-inf.
float to_float(double v);

}  // namespace gibake::gltf
