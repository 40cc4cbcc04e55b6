// C API (gibake/loader.h) over the C++ loader.
#include <cmath>
#include <cstring>
#include <new>

#include "gibake/loader.h"
#include "gibake/loader.hpp"

struct gibake_file {
  gibake::loader::BakeFile file;
};

namespace {

using gibake::loader::BakeFile;
using gibake::loader::DdgiVolume;
using gibake::loader::Error;

int finish(Error e, gibake_file* handle, gibake_file** out, char* error, size_t error_size) {
  if (error && error_size) {
    std::strncpy(error, e.message.c_str(), error_size - 1);
    error[error_size - 1] = '\0';
  }
  if (e) {
    delete handle;
    *out = nullptr;
    return static_cast<int>(e.code);
  }
  *out = handle;
  return 0;
}

const DdgiVolume* volume_of(const gibake_file* f, uint32_t volume) {
  if (!f || volume >= f->file.ddgi_volumes().size()) return nullptr;
  return &f->file.ddgi_volumes()[volume];
}

constexpr int kInvalidArgument = static_cast<int>(gibake::loader::ErrorCode::BadVolume);

// A query point and normal of finite numbers: a NaN has no nearest volume or cell to answer for.
bool finite_query(const float p[3], const float n[3]) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(p[a]) || !std::isfinite(n[a])) return false;
  return true;
}

}  // namespace

extern "C" {

int gibake_open_path(const char* path, int verify_checksums, gibake_file** out, char* error, size_t error_size) {
  if (!out || !path) return static_cast<int>(gibake::loader::ErrorCode::IoError);
  gibake_file* handle = new (std::nothrow) gibake_file;
  if (!handle) return static_cast<int>(gibake::loader::ErrorCode::IoError);
  return finish(handle->file.open(path, {verify_checksums != 0}), handle, out, error, error_size);
}

int gibake_open_memory(const void* data, size_t size, int verify_checksums, gibake_file** out, char* error,
                       size_t error_size) {
  if (!out || (!data && size)) return static_cast<int>(gibake::loader::ErrorCode::IoError);
  gibake_file* handle = new (std::nothrow) gibake_file;
  if (!handle) return static_cast<int>(gibake::loader::ErrorCode::IoError);
  const auto* bytes = static_cast<const uint8_t*>(data);
  std::vector<uint8_t> copy(bytes, bytes + size);
  return finish(handle->file.open(std::move(copy), {verify_checksums != 0}), handle, out, error, error_size);
}

void gibake_close(gibake_file* file) { delete file; }

const char* gibake_error_name(int code) {
  return gibake::loader::error_code_name(static_cast<gibake::loader::ErrorCode>(code));
}

const gibake_file_header* gibake_header(const gibake_file* file) { return file ? &file->file.header() : nullptr; }

uint32_t gibake_ddgi_volume_count(const gibake_file* file) {
  return file ? static_cast<uint32_t>(file->file.ddgi_volumes().size()) : 0;
}

const gibake_ddgi_volume* gibake_ddgi_volume_desc(const gibake_file* file, uint32_t volume) {
  const DdgiVolume* v = volume_of(file, volume);
  return v ? &v->desc() : nullptr;
}

const char* gibake_metadata(const gibake_file* file, size_t* size) {
  if (size) *size = 0;
  if (!file) return nullptr;
  for (size_t i = 0; i < file->file.sections().size(); ++i) {
    const gibake_section_entry& s = file->file.sections()[i];
    if (s.type != GIBAKE_SECTION_METADATA) continue;
    if (size) *size = static_cast<size_t>(s.size);
    return reinterpret_cast<const char*>(file->file.section_data(static_cast<uint32_t>(i)));
  }
  return nullptr;
}

int gibake_probe_sh(const gibake_file* file, uint32_t volume, uint32_t probe, float* out) {
  const DdgiVolume* v = volume_of(file, volume);
  if (!v || !out || probe >= v->probe_count()) return kInvalidArgument;
  v->sh_probe(probe, out);
  return 0;
}

int gibake_probe_position(const gibake_file* file, uint32_t volume, uint32_t probe, float out_xyz[3]) {
  const DdgiVolume* v = volume_of(file, volume);
  if (!v || !out_xyz || probe >= v->probe_count()) return kInvalidArgument;
  const gibake::loader::Vec3 p = v->probe_position(probe);
  std::memcpy(out_xyz, p.data(), sizeof(float) * 3);
  return 0;
}

uint32_t gibake_probe_state_of(const gibake_file* file, uint32_t volume, uint32_t probe) {
  const DdgiVolume* v = volume_of(file, volume);
  return v ? v->state(probe) : uint32_t(GIBAKE_PROBE_INACTIVE);
}

int gibake_sample_irradiance(const gibake_file* file, uint32_t volume, const float p[3], const float n[3],
                             float out_rgb[3]) {
  const DdgiVolume* v = volume_of(file, volume);
  if (!v || !p || !n || !out_rgb || !finite_query(p, n)) return kInvalidArgument;
  const gibake::loader::Rgb e = v->sample_irradiance({p[0], p[1], p[2]}, {n[0], n[1], n[2]});
  std::memcpy(out_rgb, e.data(), sizeof(float) * 3);
  return 0;
}

int gibake_sample_ddgi(const gibake_file* file, const float p[3], const float n[3], float out_rgb[3], int* inside) {
  if (!file || !p || !n || !out_rgb || !finite_query(p, n)) return kInvalidArgument;
  gibake::loader::Rgb e;
  const bool in = file->file.sample_ddgi({p[0], p[1], p[2]}, {n[0], n[1], n[2]}, e);
  std::memcpy(out_rgb, e.data(), sizeof(float) * 3);
  if (inside) *inside = in ? 1 : 0;
  return 0;
}

uint32_t gibake_lpv_cascade_count(const gibake_file* file) {
  return file ? static_cast<uint32_t>(file->file.lpv_cascades().size()) : 0;
}

const gibake_lpv_cascade* gibake_lpv_cascade_desc(const gibake_file* file, uint32_t cascade) {
  if (!file || cascade >= file->file.lpv_cascades().size()) return nullptr;
  return &file->file.lpv_cascades()[cascade].desc();
}

int gibake_lpv_cell_sh(const gibake_file* file, uint32_t cascade, uint32_t cell, float out[12]) {
  if (!file || !out || cascade >= file->file.lpv_cascades().size()) return kInvalidArgument;
  const gibake::loader::LpvCascade& c = file->file.lpv_cascades()[cascade];
  if (cell >= c.cell_count()) return kInvalidArgument;
  c.cell_sh(cell, out);
  return 0;
}

int gibake_sample_lpv(const gibake_file* file, const float p[3], const float n[3], float out_rgb[3]) {
  if (!file || !p || !n || !out_rgb || !finite_query(p, n)) return kInvalidArgument;
  const gibake::loader::Rgb e = file->file.sample_lpv({p[0], p[1], p[2]}, {n[0], n[1], n[2]});
  std::memcpy(out_rgb, e.data(), sizeof(float) * 3);
  return 0;
}

}  // extern "C"
