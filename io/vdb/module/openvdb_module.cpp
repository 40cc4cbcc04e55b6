// The OpenVDB module: turns the plain descriptions of io/vdb/vdb_grids.h into OpenVDB grids and
// files, and runs OpenVDB's mesh-to-distance conversion. The only gibake code that includes OpenVDB.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <type_traits>

#include "io/vdb/module_api.h"

#ifndef GIBAKE_VERSION
#define GIBAKE_VERSION "0.0.0"
#endif

namespace gibake::vdb {
namespace {

openvdb::math::Transform::Ptr make_transform(const Transform& t) {
  openvdb::math::Transform::Ptr out = openvdb::math::Transform::createLinearTransform(t.uniform_scale);
  if (t.pre_scale) out->preScale(openvdb::Vec3d((*t.pre_scale)[0], (*t.pre_scale)[1], (*t.pre_scale)[2]));
  out->postTranslate(openvdb::Vec3d(t.translate[0], t.translate[1], t.translate[2]));
  return out;
}

openvdb::Metadata::Ptr make_meta(const Meta& m) {
  switch (m.type) {
    case Meta::Type::Float:
      return openvdb::FloatMetadata(m.floats[0]).copy();
    case Meta::Type::Vec3s:
      return openvdb::Vec3SMetadata(openvdb::Vec3s(m.floats[0], m.floats[1], m.floats[2])).copy();
    case Meta::Type::Vec3i:
      return openvdb::Vec3IMetadata(openvdb::Vec3i(m.ints[0], m.ints[1], m.ints[2])).copy();
    case Meta::Type::String:
      break;
  }
  return openvdb::StringMetadata(m.text).copy();
}

openvdb::GridClass grid_class(GridClass c) {
  switch (c) {
    case GridClass::LevelSet:
      return openvdb::GRID_LEVEL_SET;
    case GridClass::FogVolume:
      return openvdb::GRID_FOG_VOLUME;
    case GridClass::Unknown:
      break;
  }
  return openvdb::GRID_UNKNOWN;
}

template <class GridT, class Value>
typename GridT::Ptr fill_grid(const Grid& g, const Value& background, const Value& tolerance,
                              Value (*value_at)(const float*)) {
  auto grid = GridT::create(background);
  if (g.dense) {
    const openvdb::CoordBBox box(openvdb::Coord(0), openvdb::Coord(g.dims[0] - 1, g.dims[1] - 1, g.dims[2] - 1));
    std::vector<Value> values;  // floats are used in place
    if constexpr (!std::is_same_v<Value, float>) {
      values.resize(g.values.size() / size_t(g.channels));
      for (size_t i = 0; i < values.size(); ++i) values[i] = value_at(&g.values[i * size_t(g.channels)]);
    }
    Value* data = values.empty() ? reinterpret_cast<Value*>(const_cast<float*>(g.values.data())) : values.data();
    openvdb::tools::Dense<Value, openvdb::tools::LayoutXYZ> dense(box, data);
    openvdb::tools::copyFromDense(dense, *grid, tolerance);
  } else {
    auto access = grid->getAccessor();
    for (size_t i = 0; i < g.coords.size(); ++i)
      access.setValue(openvdb::Coord(g.coords[i][0], g.coords[i][1], g.coords[i][2]),
                      value_at(&g.values[i * size_t(g.channels)]));
  }
  return grid;
}

float scalar(const float* v) { return v[0]; }
openvdb::Vec3s vector3(const float* v) { return openvdb::Vec3s(v[0], v[1], v[2]); }

openvdb::GridBase::Ptr make_grid(const Grid& g) {
  openvdb::GridBase::Ptr out;
  if (g.channels == 3) {
    auto grid = fill_grid<openvdb::Vec3SGrid>(g, openvdb::Vec3s(0.f), openvdb::Vec3s(g.tolerance), &vector3);
    if (g.normalized_vectors) grid->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);
    out = grid;
  } else {
    out = fill_grid<openvdb::FloatGrid>(g, g.background, g.tolerance, &scalar);
  }
  out->setName(g.name);
  out->setTransform(make_transform(g.transform));
  if (g.grid_class) out->setGridClass(grid_class(*g.grid_class));
  for (const Meta& m : g.meta) out->insertMeta(m.name, *make_meta(m));
  return out;
}

// OpenVDB's header holds a random UUID (36 characters after the magic, the three version numbers
// and the grid-offsets flag), so two writes of the same grids differ. The bake's outputs are the
// same bytes for the same inputs: the UUID is replaced by one derived from every other byte of the
// file (FNV-1a, two seeds), in the form of a version-5 (name-based) UUID.
constexpr std::streamoff kUuidOffset = 8 + 4 + 4 + 4 + 1;
constexpr size_t kUuidChars = 36;

bool looks_like_uuid(const char* text) {
  for (size_t i = 0; i < kUuidChars; ++i) {
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash != (text[i] == '-') || (!dash && !std::isxdigit(static_cast<unsigned char>(text[i])))) return false;
  }
  return true;
}

std::string content_uuid(std::fstream& file) {
  uint64_t h[2] = {0xcbf29ce484222325ull, 0x84222325cbf29ce4ull};
  char buf[1 << 16];
  std::streamoff at = 0;
  file.seekg(0);
  while (file.read(buf, sizeof buf) || file.gcount() > 0) {
    const std::streamsize n = file.gcount();
    for (std::streamsize i = 0; i < n; ++i, ++at) {
      if (at >= kUuidOffset && at < kUuidOffset + std::streamoff(kUuidChars)) continue;
      for (uint64_t& x : h) x = (x ^ static_cast<unsigned char>(buf[i])) * 0x100000001b3ull;
    }
  }
  file.clear();
  unsigned char b[16];
  for (int i = 0; i < 16; ++i) b[i] = static_cast<unsigned char>(h[i / 8] >> (8 * (i % 8)));
  b[6] = static_cast<unsigned char>((b[6] & 0x0f) | 0x50);  // version 5
  b[8] = static_cast<unsigned char>((b[8] & 0x3f) | 0x80);  // RFC 4122 variant
  char text[kUuidChars + 1];
  std::snprintf(text, sizeof text, "%02x%02x%02x%02x-%02x%02x-%02x%02x-%02x%02x-%02x%02x%02x%02x%02x%02x", b[0], b[1],
                b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15]);
  return text;
}

// The written file's UUID made its content's; "" or what went wrong.
std::string fix_uuid(const std::string& path) {
  std::fstream file(path, std::ios_base::in | std::ios_base::out | std::ios_base::binary);
  char old[kUuidChars];
  if (!file || !file.seekg(kUuidOffset) || !file.read(old, kUuidChars) || !looks_like_uuid(old))
    return "the written file has no OpenVDB header UUID where one was expected";
  const std::string uuid = content_uuid(file);
  if (!file.seekp(kUuidOffset) || !file.write(uuid.data(), std::streamsize(kUuidChars))) return "the write failed";
  file.close();
  return file ? std::string() : "the write failed (a full disk or a file-size limit)";
}

// io::File::write as OpenVDB writes it (a seekable archive), into a stream whose state is checked
// once it is closed: File::write never looks, so a full disk or a file-size limit would leave a
// truncated file that reads as written.
class CheckedVdbFile : public openvdb::io::File {
 public:
  using openvdb::io::File::File;
  std::string write_checked(const openvdb::GridPtrVec& grids, const openvdb::MetaMap& meta) const {
    std::ofstream out(filename(), std::ios_base::out | std::ios_base::binary | std::ios_base::trunc);
    if (!out) return "could not open the file for writing";
    Archive::write(out, grids, /*seekable=*/true, meta);
    out.close();
    if (!out) return "the write failed (a full disk or a file-size limit)";
    return fix_uuid(filename());
  }
};

std::string write_file(const std::string& path, const File& file) {
  try {
    openvdb::initialize();
    openvdb::GridPtrVec grids;
    for (const Grid& g : file.grids) grids.push_back(make_grid(g));
    openvdb::MetaMap meta;
    for (const Meta& m : file.meta) meta.insertMeta(m.name, *make_meta(m));
    return CheckedVdbFile(path).write_checked(grids, meta);
  } catch (const std::exception& e) {
    return e.what();
  }
}

std::string near_distances(const NearDistanceQuery& q, std::vector<float>& band) {
  try {
    openvdb::initialize();
    std::vector<openvdb::Vec3s> points(q.vertex_count);
    for (size_t i = 0; i < points.size(); ++i)
      points[i] = openvdb::Vec3s(q.positions[i * 3], q.positions[i * 3 + 1], q.positions[i * 3 + 2]);
    std::vector<openvdb::Vec3I> tris(q.triangles.size() / 3);
    for (size_t t = 0; t < tris.size(); ++t)
      tris[t] = openvdb::Vec3I(q.triangles[t * 3], q.triangles[t * 3 + 1], q.triangles[t * 3 + 2]);
    const double h = q.voxel_size;
    openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(h);
    xform->postTranslate(openvdb::Vec3d(q.origin[0] + 0.5 * h, q.origin[1] + 0.5 * h, q.origin[2] + 0.5 * h));
    // A band of 1 voxel: OpenVDB voxelizes the triangles and stops (no band expansion).
    const openvdb::FloatGrid::Ptr near =
        openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xform, points, tris, {}, 1.f);
    const int64_t X = q.dims[0], Y = q.dims[1], Z = q.dims[2];
    band.assign(size_t(X * Y * Z), std::numeric_limits<float>::infinity());
    const openvdb::CoordBBox inside(openvdb::Coord(0), openvdb::Coord(q.dims[0] - 1, q.dims[1] - 1, q.dims[2] - 1));
    for (auto it = near->cbeginValueOn(); it; ++it) {  // voxels, and tiles (not expected in a 1-voxel band)
      openvdb::CoordBBox box = it.getBoundingBox();
      box.intersect(inside);
      if (box.empty()) continue;
      for (int32_t z = box.min().z(); z <= box.max().z(); ++z)
        for (int32_t y = box.min().y(); y <= box.max().y(); ++y)
          for (int32_t x = box.min().x(); x <= box.max().x(); ++x) band[size_t(x + X * (y + Y * int64_t(z)))] = *it;
    }
  } catch (const std::exception& e) {
    return e.what();
  }
  return {};
}

const ModuleApi kApi = {kModuleAbi,  GIBAKE_VERSION, sizeof(Grid), sizeof(File), sizeof(NearDistanceQuery),
                        &write_file, &near_distances};

}  // namespace
}  // namespace gibake::vdb

extern "C" __attribute__((visibility("default"))) const gibake::vdb::ModuleApi* gibake_openvdb_module() {
  return &gibake::vdb::kApi;
}
