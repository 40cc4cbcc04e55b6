// Accessor validation and decoding.
#include "io/gltf/accessor_read.h"

#include <cstring>

namespace gibake::gltf {
namespace {

constexpr size_t kMaxViewlessCount = size_t(1) << 22;  // accessors without a bufferView (all zeros)

// A checked byte range inside one buffer.
struct Span {
  const unsigned char* data = nullptr;
  size_t size = 0;
};

// bufferViews[v] as a checked span of its buffer.
Status view_span(const ImportEnv& env, int v, Span& out) {
  const auto& m = *env.model;
  if (v < 0 || size_t(v) >= m.bufferViews.size())
    return env.invalid(at("bufferViews", size_t(v < 0 ? 0 : v)), "bufferView index out of range");
  const auto& view = m.bufferViews[size_t(v)];
  if (view.buffer < 0 || size_t(view.buffer) >= m.buffers.size())
    return env.invalid(at("bufferViews", size_t(v)), "buffer index out of range");
  const auto& buf = m.buffers[size_t(view.buffer)].data;
  if (view.byteOffset > buf.size() || view.byteLength > buf.size() - view.byteOffset)
    return env.invalid(at("bufferViews", size_t(v)),
                       "byteOffset " + std::to_string(view.byteOffset) + " + byteLength " +
                           std::to_string(view.byteLength) + " exceeds the buffer's " +
                           std::to_string(buf.size()) + " bytes");
  out.data = buf.data() + view.byteOffset;
  out.size = view.byteLength;
  return Status::ok();
}

// True when offset + (count-1)*stride + elem <= size, without overflow.
bool range_fits(size_t offset, size_t count, size_t stride, size_t elem, size_t size) {
  if (count == 0) return offset <= size;
  if (offset > size || elem > size - offset) return false;
  size_t room = size - offset - elem;
  return stride == 0 || (count - 1) <= room / stride;
}

float read_component(const unsigned char* p, int ctype, bool normalized) {
  switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); return f; }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v; std::memcpy(&v, p, 1);
      return normalized ? std::max(float(v) / 127.f, -1.f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(*p) / 255.f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v; std::memcpy(&v, p, 2);
      return normalized ? std::max(float(v) / 32767.f, -1.f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v; std::memcpy(&v, p, 2);
      return normalized ? float(v) / 65535.f : float(v);
    }
    default: {
      uint32_t v; std::memcpy(&v, p, 4);
      return normalized ? float(double(v) / 4294967295.0) : float(v);
    }
  }
}

uint32_t read_uint(const unsigned char* p, int ctype) {
  if (ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return *p;
  if (ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) { uint16_t v; std::memcpy(&v, p, 2); return v; }
  uint32_t v; std::memcpy(&v, p, 4); return v;
}

bool is_index_type(int ctype) {
  return ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
         ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
         ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
}

// The accessor's checked layout.
struct Layout {
  Span span;  // empty data when no bufferView
  size_t offset = 0, stride = 0, elem = 0, count = 0;
  int ctype = 0, comps = 0, cbytes = 0;
};

Status validate_layout(const ImportEnv& env, int index, Layout& L) {
  const auto& m = *env.model;
  std::string where = at("accessors", size_t(index < 0 ? 0 : index));
  if (index < 0 || size_t(index) >= m.accessors.size()) return env.invalid(where, "accessor index out of range");
  const auto& a = m.accessors[size_t(index)];
  L.ctype = a.componentType;
  L.cbytes = component_bytes(a.componentType);
  L.comps = type_components(a.type);
  if (L.cbytes == 0) return env.invalid(where, "unknown componentType " + std::to_string(a.componentType));
  if (L.comps == 0) return env.invalid(where, "unknown type");
  if (a.count == 0) return env.invalid(where, "count is 0");
  L.count = a.count;
  L.elem = size_t(L.cbytes) * size_t(L.comps);
  if (a.bufferView < 0) {
    if (a.count > kMaxViewlessCount) return env.invalid(where, "count too large for an accessor without bufferView");
    return Status::ok();
  }
  GIBAKE_TRY(view_span(env, a.bufferView, L.span));
  size_t stride = m.bufferViews[size_t(a.bufferView)].byteStride;
  if (stride != 0 && (stride < L.elem || stride > 252 || stride % size_t(L.cbytes) != 0))
    return env.invalid(at("bufferViews", size_t(a.bufferView)), "invalid byteStride " + std::to_string(stride));
  L.stride = stride ? stride : L.elem;
  L.offset = a.byteOffset;
  if (L.offset % size_t(L.cbytes) != 0) return env.invalid(where, "byteOffset not aligned to the component size");
  if (!range_fits(L.offset, L.count, L.stride, L.elem, L.span.size))
    return env.invalid(where, "byteOffset " + std::to_string(L.offset) + " + count " + std::to_string(L.count) +
                                  " x stride " + std::to_string(L.stride) + " exceeds bufferView " +
                                  std::to_string(a.bufferView) + " (" + std::to_string(L.span.size) + " bytes)");
  return Status::ok();
}

Status check_allowed(const ImportEnv& env, int index, const std::vector<int>& allowed) {
  int type = env.model->accessors[size_t(index)].type;
  for (int t : allowed)
    if (t == type) return Status::ok();
  return env.invalid(at("accessors", size_t(index)), "accessor type not allowed here");
}

// Applies accessors[index].sparse to `out` (count*comps floats).
Status apply_sparse(const ImportEnv& env, int index, const Layout& L, std::vector<float>& out) {
  const auto& a = env.model->accessors[size_t(index)];
  std::string where = at("accessors", size_t(index)) + ".sparse";
  if (a.sparse.count <= 0 || size_t(a.sparse.count) > L.count)
    return env.invalid(where, "sparse count " + std::to_string(a.sparse.count) + " out of range");
  size_t n = size_t(a.sparse.count);
  int ict = a.sparse.indices.componentType;
  if (!is_index_type(ict)) return env.invalid(where, "sparse indices componentType must be unsigned");
  Span is, vs;
  GIBAKE_TRY(view_span(env, a.sparse.indices.bufferView, is));
  GIBAKE_TRY(view_span(env, a.sparse.values.bufferView, vs));
  size_t ib = size_t(component_bytes(ict));
  if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0 ||
      !range_fits(size_t(a.sparse.indices.byteOffset), n, ib, ib, is.size) ||
      !range_fits(size_t(a.sparse.values.byteOffset), n, L.elem, L.elem, vs.size))
    return env.invalid(where, "sparse indices or values exceed their bufferView");
  for (size_t k = 0; k < n; ++k) {
    uint32_t target = read_uint(is.data + size_t(a.sparse.indices.byteOffset) + k * ib, ict);
    if (target >= L.count)
      return env.invalid(where, "sparse index " + std::to_string(target) + " >= count " + std::to_string(L.count));
    const unsigned char* src = vs.data + size_t(a.sparse.values.byteOffset) + k * L.elem;
    for (int c = 0; c < L.comps; ++c)
      out[size_t(target) * size_t(L.comps) + size_t(c)] = read_component(src + size_t(c) * size_t(L.cbytes), L.ctype, a.normalized);
  }
  return Status::ok();
}

}  // namespace

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

int component_bytes(int ctype) {
  switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

Status accessor_count(const ImportEnv& env, int index, size_t& count) {
  const auto& m = *env.model;
  if (index < 0 || size_t(index) >= m.accessors.size())
    return env.invalid(at("accessors", size_t(index < 0 ? 0 : index)), "accessor index out of range");
  count = m.accessors[size_t(index)].count;
  return Status::ok();
}

Status read_float_accessor(const ImportEnv& env, int index, const std::vector<int>& allowed_types,
                           std::vector<float>& out, int& components) {
  Layout L;
  GIBAKE_TRY(validate_layout(env, index, L));
  GIBAKE_TRY(check_allowed(env, index, allowed_types));
  const auto& a = env.model->accessors[size_t(index)];
  components = L.comps;
  out.assign(L.count * size_t(L.comps), 0.f);
  if (L.span.data) {
    for (size_t i = 0; i < L.count; ++i) {
      const unsigned char* e = L.span.data + L.offset + i * L.stride;
      for (int c = 0; c < L.comps; ++c)
        out[i * size_t(L.comps) + size_t(c)] = read_component(e + size_t(c) * size_t(L.cbytes), L.ctype, a.normalized);
    }
  }
  if (a.sparse.isSparse) GIBAKE_TRY(apply_sparse(env, index, L, out));
  return Status::ok();
}

Status read_index_accessor(const ImportEnv& env, int index, std::vector<uint32_t>& out) {
  Layout L;
  GIBAKE_TRY(validate_layout(env, index, L));
  const auto& a = env.model->accessors[size_t(index)];
  std::string where = at("accessors", size_t(index));
  if (L.comps != 1 || !is_index_type(L.ctype) || a.normalized)
    return env.invalid(where, "indices must be SCALAR unsigned byte/short/int");
  if (a.sparse.isSparse) return env.invalid(where, "sparse index accessors are not supported");
  out.assign(L.count, 0u);  // no bufferView: all zeros
  if (!L.span.data) return Status::ok();
  for (size_t i = 0; i < L.count; ++i) out[i] = read_uint(L.span.data + L.offset + i * L.stride, L.ctype);
  return Status::ok();
}

}  // namespace gibake::gltf
