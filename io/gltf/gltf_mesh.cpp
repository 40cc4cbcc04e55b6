// Primitive decoding for uncompressed glTF meshes and the shared post-processing.
#include "io/gltf/gltf_mesh.h"

#include <cmath>

#include "io/gltf/accessor_read.h"
#include "io/gltf/draco_decode.h"
#include "io/gltf/gltf_deform.h"
#include "io/gltf/gltf_tiny.h"

namespace gibake::gltf {
namespace {

using V3 = std::array<float, 3>;

V3 vtx(const std::vector<float>& p, uint32_t i) { return {p[3 * size_t(i)], p[3 * size_t(i) + 1], p[3 * size_t(i) + 2]}; }

V3 face_cross(const std::vector<float>& p, uint32_t a, uint32_t b, uint32_t c) {
  V3 A = vtx(p, a), B = vtx(p, b), C = vtx(p, c);
  V3 e1{B[0] - A[0], B[1] - A[1], B[2] - A[2]}, e2{C[0] - A[0], C[1] - A[1], C[2] - A[2]};
  return {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
}

void normalise_into(float* n) {
  double l = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
  if (!(l > 1e-30) || !std::isfinite(l)) {
    n[0] = 0.f, n[1] = 0.f, n[2] = 1.f;
    return;
  }
  for (int k = 0; k < 3; ++k) n[k] = float(n[k] / l);
}

bool normals_usable(const std::vector<float>& n) {
  for (size_t i = 0; i + 2 < n.size(); i += 3) {
    double l = double(n[i]) * n[i] + double(n[i + 1]) * n[i + 1] + double(n[i + 2]) * n[i + 2];
    if (!std::isfinite(l) || l < 1e-12) return false;
  }
  return true;
}

// Gives every triangle its own three vertices (for flat normals).
void unshare(PrimitiveData& d) {
  PrimitiveData f;
  f.material = d.material;
  f.draco = d.draco;
  auto copy = [](const std::vector<float>& src, std::vector<float>& dst, size_t n, uint32_t i) {
    if (!src.empty()) dst.insert(dst.end(), src.begin() + long(n * i), src.begin() + long(n * i + n));
  };
  for (size_t k = 0; k < d.indices.size(); ++k) {
    uint32_t i = d.indices[k];
    copy(d.positions, f.positions, 3, i);
    copy(d.uvs, f.uvs, 2, i);
    copy(d.colors, f.colors, 4, i);
    copy(d.joints, f.joints, size_t(d.influences), i);
    copy(d.joint_weights, f.joint_weights, size_t(d.influences), i);
    f.indices.push_back(uint32_t(k));
  }
  f.influences = d.influences;
  d = std::move(f);
}

Status read_attribute(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                      const char* name, std::vector<int> types, size_t vertices, std::vector<float>& out,
                      int& comps) {
  auto it = p.attributes.find(name);
  if (it == p.attributes.end()) return Status::ok();
  GIBAKE_TRY(read_float_accessor(env, it->second, types, out, comps));
  if (vertices != size_t(-1) && out.size() / size_t(comps) != vertices)
    return env.invalid(where, std::string(name) + " count differs from POSITION count");
  return Status::ok();
}

Status read_plain_attributes(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                             PrimitiveData& d) {
  int comps = 0;
  if (!p.attributes.count("POSITION")) return Status::ok();
  GIBAKE_TRY(read_attribute(env, where, p, "POSITION", {TINYGLTF_TYPE_VEC3}, size_t(-1), d.positions, comps));
  for (float f : d.positions)
    if (!std::isfinite(f)) return env.invalid(where, "POSITION contains NaN or infinity");
  size_t n = d.vertex_count();
  GIBAKE_TRY(read_attribute(env, where, p, "NORMAL", {TINYGLTF_TYPE_VEC3}, n, d.normals, comps));
  GIBAKE_TRY(read_attribute(env, where, p, "TEXCOORD_0", {TINYGLTF_TYPE_VEC2}, n, d.uvs, comps));
  std::vector<float> col;
  GIBAKE_TRY(read_attribute(env, where, p, "COLOR_0", {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, n, col, comps));
  if (!col.empty()) {
    d.colors.resize(n * 4, 1.f);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < comps; ++c) d.colors[i * 4 + size_t(c)] = col[i * size_t(comps) + size_t(c)];
  }
  return Status::ok();
}

Status read_plain_indices(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p,
                          PrimitiveData& d) {
  std::vector<uint32_t> raw;
  int indices = primitive_indices(p);
  if (indices >= 0) {
    GIBAKE_TRY(read_index_accessor(env, indices, raw));
    for (uint32_t i : raw)
      if (i >= d.vertex_count())
        return env.invalid(where, "index " + std::to_string(i) + " >= vertex count " + std::to_string(d.vertex_count()));
  } else {
    raw.resize(d.vertex_count());
    for (size_t i = 0; i < raw.size(); ++i) raw[i] = uint32_t(i);
  }
  int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode == TINYGLTF_MODE_TRIANGLES && raw.size() % 3 != 0)
    env.ctx->warning(env.file + ": " + where + ": index count not a multiple of 3; extra indices ignored");
  d.indices = triangulate(mode, raw);
  return Status::ok();
}

bool is_skipped_mode(int mode) {
  return mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP ||
         mode == TINYGLTF_MODE_LINE_STRIP;
}

Status finish(const ImportEnv& env, const std::string& where, const tinygltf::Primitive& p, bool indexed,
              PrimitiveData& d) {
  const auto& m = *env.model;
  if (p.material >= 0 && size_t(p.material) >= m.materials.size())
    return env.invalid(where, "material index " + std::to_string(p.material) + " out of range");
  d.material = p.material < 0 ? -1 : p.material;
  // glTF requires flat normals where a primitive gives none. Where it gives broken ones, the shared
  // vertices of an indexed primitive keep the smooth shading its author meant.
  const bool given = !d.normals.empty();
  if (given && !normals_usable(d.normals)) {
    env.ctx->warning(env.file + ": " + where + ": NORMAL has zero or non-finite vectors; regenerated");
    d.normals.clear();
  }
  if (d.normals.empty()) generate_normals(d, given && indexed);
  for (size_t i = 0; i + 2 < d.normals.size(); i += 3) normalise_into(&d.normals[i]);
  return Status::ok();
}

}  // namespace

int primitive_indices(const tinygltf::Primitive& p) {
  if (p.indices >= 0) return p.indices;
  auto it = p.extensions.find("GIBAKE_indices");
  if (it == p.extensions.end() || !it->second.IsObject() || !it->second.Get("accessor").IsNumber()) return -1;
  double d = it->second.Get("accessor").GetNumberAsDouble();
  return (d >= 0 && d < 2147483647.0) ? int(d) : -1;
}

std::vector<uint32_t> triangulate(int mode, const std::vector<uint32_t>& idx) {
  std::vector<uint32_t> t;
  size_t n = idx.size();
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    t.assign(idx.begin(), idx.begin() + long(n - n % 3));
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 0; i + 2 < n; ++i) {
      bool odd = i % 2 == 1;
      t.insert(t.end(), {idx[i], idx[odd ? i + 2 : i + 1], idx[odd ? i + 1 : i + 2]});
    }
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (size_t i = 1; i + 1 < n; ++i) t.insert(t.end(), {idx[i], idx[i + 1], idx[0]});
  }
  return t;
}

void generate_normals(PrimitiveData& d, bool smooth) {
  if (!smooth) unshare(d);
  d.normals.assign(d.positions.size(), 0.f);
  for (size_t t = 0; t + 2 < d.indices.size(); t += 3) {
    uint32_t a = d.indices[t], b = d.indices[t + 1], c = d.indices[t + 2];
    V3 n = face_cross(d.positions, a, b, c);
    if (!smooth) normalise_into(n.data());
    for (uint32_t v : {a, b, c})
      for (int k = 0; k < 3; ++k) d.normals[3 * size_t(v) + size_t(k)] += n[size_t(k)];
  }
}

Status decode_primitive(const ImportEnv& env, size_t mesh, size_t prim, const std::vector<double>& weights,
                        PrimitiveData& out) {
  const auto& p = env.model->meshes[mesh].primitives[prim];
  std::string where = at("meshes", mesh, "primitives", prim);
  out = PrimitiveData();
  int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (is_skipped_mode(mode)) {
    env.ctx->warning(env.file + ": " + where + ": points/lines primitive skipped");
    out.skipped = true;
    return Status::ok();
  }
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
    return env.invalid(where, "unknown primitive mode " + std::to_string(mode));
  bool indexed = true;
  bool morphed = false;
  for (size_t t = 0; t < p.targets.size() && t < weights.size(); ++t) morphed = morphed || weights[t] != 0.0;
  if (p.extensions.count("KHR_draco_mesh_compression")) {
    GIBAKE_TRY(decode_draco_primitive(env, mesh, prim, out));
    out.draco = true;
    // The extension compresses the base attributes alone, in its own vertex order.
    if (morphed)
      env.ctx->warning(env.file + ": " + where + ": morph targets of a Draco-compressed primitive are not applied");
  } else {
    GIBAKE_TRY(read_plain_attributes(env, where, p, out));
    if (out.positions.empty()) {
      env.ctx->warning(env.file + ": " + where + ": no POSITION; primitive skipped");
      out.skipped = true;
      return Status::ok();
    }
    GIBAKE_TRY(read_plain_indices(env, where, p, out));
    GIBAKE_TRY(read_skin_attributes(env, where, p, out));
    if (morphed) GIBAKE_TRY(apply_morph_targets(env, where, p, weights, out));
    indexed = primitive_indices(p) >= 0;
  }
  return finish(env, where, p, indexed, out);
}

}  // namespace gibake::gltf
