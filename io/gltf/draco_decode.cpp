// Draco decoding with validation.
#include "io/gltf/draco_decode.h"

#include <draco/compression/decode.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "io/gltf/accessor_read.h"
#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {
namespace {

bool value_int(const tinygltf::Value& v, int& out) {
  if (v.IsInt()) return out = v.GetNumberAsInt(), true;
  if (!v.IsReal()) return false;
  double d = v.GetNumberAsDouble();
  if (!(d >= 0 && d <= double(std::numeric_limits<int>::max())) || d != std::floor(d)) return false;
  out = int(d);
  return true;
}

struct DracoRefs {
  int buffer_view = -1;
  std::map<std::string, int> attributes;  // glTF attribute name -> Draco unique id
};

Status parse_extension(const ImportEnv& env, const std::string& where, const tinygltf::Value& ext,
                       DracoRefs& r) {
  if (!ext.IsObject()) return env.invalid(where, "KHR_draco_mesh_compression is not an object");
  if (!value_int(ext.Get("bufferView"), r.buffer_view))
    return env.invalid(where, "KHR_draco_mesh_compression.bufferView missing or not an index");
  const tinygltf::Value& atts = ext.Get("attributes");
  if (!atts.IsObject()) return env.invalid(where, "KHR_draco_mesh_compression.attributes missing");
  for (const std::string& k : atts.Keys()) {
    int id = -1;
    if (!value_int(atts.Get(k), id) || id < 0)
      return env.invalid(where, "KHR_draco_mesh_compression.attributes." + k + " is not an id");
    r.attributes[k] = id;
  }
  if (!r.attributes.count("POSITION")) return env.invalid(where, "Draco attributes lack POSITION");
  return Status::ok();
}

Status stream_span(const ImportEnv& env, const std::string& where, int v, const char*& data, size_t& size) {
  const auto& m = *env.model;
  if (v < 0 || size_t(v) >= m.bufferViews.size()) return env.invalid(where, "Draco bufferView index out of range");
  const auto& view = m.bufferViews[size_t(v)];
  std::string vw = at("bufferViews", size_t(v));
  if (view.buffer < 0 || size_t(view.buffer) >= m.buffers.size()) return env.invalid(vw, "buffer index out of range");
  const auto& buf = m.buffers[size_t(view.buffer)].data;
  if (view.byteOffset > buf.size() || view.byteLength > buf.size() - view.byteOffset || view.byteLength == 0)
    return env.invalid(vw, "Draco stream range lies outside its buffer");
  data = reinterpret_cast<const char*>(buf.data() + view.byteOffset);
  size = view.byteLength;
  return Status::ok();
}

// Counts the glTF accessors promise, checked against the limits before decoding.
Status expected_counts(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                       size_t& points, size_t& corners) {
  auto it = p.attributes.find("POSITION");
  if (it == p.attributes.end()) return env.invalid(where, "Draco primitive has no POSITION accessor");
  GIBAKE_TRY(accessor_count(env, it->second, points));
  int indices = primitive_indices(p);
  if (indices < 0) return env.invalid(where, "Draco primitive has no indices accessor");
  GIBAKE_TRY(accessor_count(env, indices, corners));
  if (corners % 3 != 0 || corners / 3 > env.limits().max_triangles || points > env.limits().max_triangles * 3)
    return env.invalid(where, "Draco accessor counts are invalid or over the limits");
  return Status::ok();
}

// KHR_draco_mesh_compression is specified against Draco bitstream 2.2; the 2017 drafts wrote 2.0
// and 2.1 streams, which current decoders may read differently or not at all.
Status check_header(const ImportEnv& env, const std::string& where, const char* data, size_t size) {
  if (size < 8 || std::string(data, 5) != "DRACO") return env.invalid(where, "not a Draco stream (no DRACO header)");
  int major = uint8_t(data[5]), minor = uint8_t(data[6]);
  if (major != 2 || minor != 2)
    return env.invalid(where, "Draco bitstream version " + std::to_string(major) + "." + std::to_string(minor) +
                                  " is not the 2.2 that KHR_draco_mesh_compression requires (legacy 2017 draft?)");
  return Status::ok();
}

Status decode_mesh(const ImportEnv& env, const std::string& where, const char* data, size_t size,
                   std::unique_ptr<draco::Mesh>& mesh) {
  GIBAKE_TRY(check_header(env, where, data, size));
  draco::DecoderBuffer buf;
  buf.Init(data, size);
  auto type = draco::Decoder::GetEncodedGeometryType(&buf);
  if (!type.ok()) return env.invalid(where, "Draco stream unreadable: " + type.status().error_msg_string());
  if (type.value() != draco::TRIANGULAR_MESH) return env.invalid(where, "Draco stream is not a triangle mesh");
  draco::Decoder dec;
  auto res = dec.DecodeMeshFromBuffer(&buf);
  if (!res.ok())
    return env.invalid(where, "Draco decode failed (truncated, corrupt or legacy stream): " +
                                  res.status().error_msg_string());
  mesh = std::move(res).value();
  if (!mesh) return env.invalid(where, "Draco decode produced no mesh");
  return Status::ok();
}

// Reads one Draco attribute for every point into `out` (`comps` floats per point).
Status read_attribute(const ImportEnv& env, const std::string& where, const draco::Mesh& mesh,
                      const std::string& name, int id, int min_comps, int max_comps, std::vector<float>& out,
                      int& comps) {
  const draco::PointAttribute* att = mesh.GetAttributeByUniqueId(uint32_t(id));
  if (!att) return env.invalid(where, "Draco attribute id " + std::to_string(id) + " (" + name + ") not in the stream");
  comps = att->num_components();
  if (comps < min_comps || comps > max_comps)
    return env.invalid(where, "Draco attribute " + name + " has " + std::to_string(comps) + " components");
  if (!att->buffer() || att->byte_stride() <= 0) return env.invalid(where, "Draco attribute " + name + " has no data");
  size_t values = att->size();
  size_t bytes = size_t(att->buffer()->data_size());
  size_t off = size_t(att->byte_offset() < 0 ? 0 : att->byte_offset());
  size_t stored = off > bytes ? 0 : (bytes - off) / size_t(att->byte_stride());
  size_t n = mesh.num_points();
  out.resize(n * size_t(comps));
  for (size_t i = 0; i < n; ++i) {
    draco::PointIndex pi(static_cast<uint32_t>(i));
    if (!att->is_mapping_identity() && i >= att->indices_map_size())
      return env.invalid(where, "Draco attribute " + name + " mapping is short");
    draco::AttributeValueIndex avi = att->mapped_index(pi);
    if (avi.value() >= values || avi.value() >= stored)
      return env.invalid(where, "Draco attribute " + name + " value index out of range");
    if (!att->ConvertValue<float>(avi, int8_t(comps), &out[i * size_t(comps)]))
      return env.invalid(where, "Draco attribute " + name + " could not be converted");
  }
  return Status::ok();
}

Status read_faces(const ImportEnv& env, const std::string& where, const draco::Mesh& mesh,
                  std::vector<uint32_t>& idx) {
  idx.resize(size_t(mesh.num_faces()) * 3);
  for (uint32_t f = 0; f < mesh.num_faces(); ++f) {
    const auto& face = mesh.face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      uint32_t v = face[k].value();
      if (v >= mesh.num_points()) return env.invalid(where, "Draco face refers to a missing point");
      idx[size_t(f) * 3 + size_t(k)] = v;
    }
  }
  return Status::ok();
}

Status read_optional(const ImportEnv& env, const std::string& where, const draco::Mesh& mesh,
                     const DracoRefs& r, PrimitiveData& out) {
  int comps = 0;
  auto id = [&](const char* n) { auto it = r.attributes.find(n); return it == r.attributes.end() ? -1 : it->second; };
  if (id("NORMAL") >= 0) GIBAKE_TRY(read_attribute(env, where, mesh, "NORMAL", id("NORMAL"), 3, 3, out.normals, comps));
  if (id("TEXCOORD_0") >= 0)
    GIBAKE_TRY(read_attribute(env, where, mesh, "TEXCOORD_0", id("TEXCOORD_0"), 2, 2, out.uvs, comps));
  // Skinning sets, 4 joints a set, while both halves of a set are in the stream.
  int sets = 0;
  while (id(("JOINTS_" + std::to_string(sets)).c_str()) >= 0 && id(("WEIGHTS_" + std::to_string(sets)).c_str()) >= 0)
    ++sets;
  const size_t points = mesh.num_points();
  out.joints.assign(points * 4 * size_t(sets), 0.f);
  out.joint_weights.assign(points * 4 * size_t(sets), 0.f);
  for (int set = 0; set < sets; ++set)
    for (const char* prefix : {"JOINTS_", "WEIGHTS_"}) {
      const std::string name = prefix + std::to_string(set);
      std::vector<float> v;
      GIBAKE_TRY(read_attribute(env, where, mesh, name, id(name.c_str()), 4, 4, v, comps));
      std::vector<float>& dst = prefix[0] == 'J' ? out.joints : out.joint_weights;
      for (size_t i = 0; i < points; ++i)
        for (size_t c = 0; c < 4; ++c) dst[i * 4 * size_t(sets) + 4 * size_t(set) + c] = v[4 * i + c];
    }
  out.influences = 4 * sets;
  if (id("COLOR_0") >= 0) {
    std::vector<float> col;
    GIBAKE_TRY(read_attribute(env, where, mesh, "COLOR_0", id("COLOR_0"), 3, 4, col, comps));
    size_t n = mesh.num_points();
    out.colors.assign(n * 4, 1.f);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < comps; ++c) out.colors[i * 4 + size_t(c)] = col[i * size_t(comps) + size_t(c)];
  }
  return Status::ok();
}

// glTF requires POSITION's min and max, and a decoded stream should lie within them (up to its
// quantisation). Positions far outside mean the stream and the accessor disagree (attribute ids
// swapped, a broken quantisation range): the mesh is still placed as decoded, and said so.
void check_position_bounds(const ImportEnv& env, const std::string& where, const tinygltf::Accessor& a,
                           const std::vector<float>& positions) {
  if (a.minValues.size() != 3 || a.maxValues.size() != 3 || positions.empty()) return;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = positions[size_t(k)];
  for (size_t i = 0; i + 2 < positions.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], positions[i + size_t(k)]);
      hi[k] = std::max(hi[k], positions[i + size_t(k)]);
    }
  double extent = 0.0;
  for (int k = 0; k < 3; ++k) extent = std::max(extent, a.maxValues[size_t(k)] - a.minValues[size_t(k)]);
  // A hundredth of the box (or of a metre, for a flat or point box): far beyond any quantisation.
  const double slack = 0.01 * std::max(extent, 1.0);
  for (int k = 0; k < 3; ++k)
    if (lo[k] < a.minValues[size_t(k)] - slack || hi[k] > a.maxValues[size_t(k)] + slack) {
      char text[192];
      std::snprintf(text, sizeof text,
                    ": decoded positions span %g..%g on axis %c, outside the POSITION accessor's min/max %g..%g",
                    double(lo[k]), double(hi[k]), "xyz"[k], a.minValues[size_t(k)], a.maxValues[size_t(k)]);
      env.ctx->warning(env.file + ": " + where + text);
      return;
    }
}

}  // namespace

Status decode_draco_primitive(const ImportEnv& env, size_t mesh_i, size_t prim, PrimitiveData& out) {
  const auto& p = env.model->meshes[mesh_i].primitives[prim];
  std::string where = at("meshes", mesh_i, "primitives", prim) + ".KHR_draco_mesh_compression";
  DracoRefs refs;
  GIBAKE_TRY(parse_extension(env, where, p.extensions.at("KHR_draco_mesh_compression"), refs));
  for (const auto& kv : p.attributes)
    if (!refs.attributes.count(kv.first) && (kv.first == "NORMAL" || kv.first == "TEXCOORD_0" || kv.first == "COLOR_0"))
      env.ctx->warning(env.file + ": " + where + ": " + kv.first + " is not in the Draco stream; ignored");
  const char* data = nullptr;
  size_t size = 0, points = 0, corners = 0;
  GIBAKE_TRY(stream_span(env, where, refs.buffer_view, data, size));
  GIBAKE_TRY(expected_counts(env, where, p, points, corners));
  std::unique_ptr<draco::Mesh> mesh;
  GIBAKE_TRY(decode_mesh(env, where, data, size, mesh));
  if (mesh->num_points() != points)
    return env.invalid(where, "decoded " + std::to_string(mesh->num_points()) + " points but the POSITION accessor says " +
                                  std::to_string(points));
  if (size_t(mesh->num_faces()) * 3 != corners)
    return env.invalid(where, "decoded " + std::to_string(mesh->num_faces()) + " faces but the indices accessor says " +
                                  std::to_string(corners) + " indices");
  int comps = 0;
  GIBAKE_TRY(read_attribute(env, where, *mesh, "POSITION", refs.attributes["POSITION"], 3, 3, out.positions, comps));
  for (float f : out.positions)
    if (!std::isfinite(f)) return env.invalid(where, "decoded POSITION contains NaN or infinity");
  check_position_bounds(env, where, env.model->accessors[size_t(p.attributes.at("POSITION"))], out.positions);
  GIBAKE_TRY(read_optional(env, where, *mesh, refs, out));
  return read_faces(env, where, *mesh, out.indices);
}

}  // namespace gibake::gltf
