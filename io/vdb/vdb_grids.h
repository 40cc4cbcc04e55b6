// OpenVDB files and OpenVDB's mesh distances, described in plain data. OpenVDB lives in a module of
// its own (io/vdb/module/), loaded the first time one of these is used (io/vdb/vdb_module.h):
// linked into gibake, its tens of thousands of symbol bindings would slow every command's start.
// Everything here is header-only and free of OpenVDB, so both sides share it.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace gibake::vdb {

enum class GridClass : uint8_t { Unknown, LevelSet, FogVolume };

// Index space to world: a uniform scale, then (optionally) a per-axis scale applied before it, then
// a translation, in the order OpenVDB composes them (createLinearTransform, preScale, postTranslate).
struct Transform {
  double uniform_scale = 1.0;
  std::optional<std::array<double, 3>> pre_scale;
  std::array<double, 3> translate{0.0, 0.0, 0.0};
};

// One typed metadata entry (the kinds gibake writes).
struct Meta {
  enum class Type : uint8_t { String, Float, Vec3s, Vec3i };
  Type type = Type::String;
  std::string name;
  std::string text;
  std::array<float, 3> floats{0.f, 0.f, 0.f};
  std::array<int32_t, 3> ints{0, 0, 0};

  static Meta string(std::string name, std::string text) { return {Type::String, std::move(name), std::move(text)}; }
  static Meta number(std::string name, float value) { return {Type::Float, std::move(name), {}, {value, 0.f, 0.f}}; }
  static Meta vec3s(std::string name, const std::array<float, 3>& v) { return {Type::Vec3s, std::move(name), {}, v}; }
  static Meta vec3i(std::string name, const std::array<int32_t, 3>& v) {
    return {Type::Vec3i, std::move(name), {}, {0.f, 0.f, 0.f}, v};
  }
};

// A FloatGrid (1 channel) or Vec3SGrid (3). Values are either dense over `dims` (index x + X*(y +
// Y*z)), where voxels within `tolerance` of the background stay inactive (a negative tolerance keeps
// every voxel active), or sparse: one value (`channels` floats) per entry of `coords`.
struct Grid {
  std::string name;
  int channels = 1;
  float background = 0.f;               // FloatGrid only; a Vec3SGrid's is zero
  std::optional<GridClass> grid_class;  // stored only when set
  bool normalized_vectors = false;      // Vec3SGrid: VEC_COVARIANT_NORMALIZE
  Transform transform;
  std::vector<Meta> meta;
  bool dense = false;
  std::array<int32_t, 3> dims{0, 0, 0};
  float tolerance = 0.f;
  std::vector<std::array<int32_t, 3>> coords;
  std::vector<float> values;
};

struct File {
  std::vector<Grid> grids;
  std::vector<Meta> meta;  // file-level
};

// OpenVDB's unsigned distance field of a triangle mesh, one voxel of band, on a voxel grid whose
// voxel (i,j,k) has its centre at origin + (ijk + 0.5) * voxel_size.
struct NearDistanceQuery {
  const float* positions = nullptr;  // xyz per vertex
  size_t vertex_count = 0;
  std::vector<uint32_t> triangles;  // three vertex indices each, finite positions only
  double voxel_size = 0.0;
  std::array<float, 3> origin{0.f, 0.f, 0.f};
  std::array<int32_t, 3> dims{0, 0, 0};
};

}  // namespace gibake::vdb
