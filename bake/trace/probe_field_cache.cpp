// Probe field reads shared per key (probe_field_cache.h).
#include "bake/trace/probe_field_cache.h"

#include <algorithm>
#include <cmath>

#include "gibake/loader.hpp"
#include "kernels/octahedral.h"

namespace gibake {

using kernels::float3;

namespace {

size_t slot_of(const CachedProbeField::Key& k, int bits) {
  uint64_t x = uint64_t(uint32_t(k.cell[0])) * 0x9E3779B97F4A7C15ull;
  x ^= (x >> 29) + uint64_t(uint32_t(k.cell[1])) * 0xC2B2AE3D27D4EB4Full;
  x ^= (x >> 31) + uint64_t(uint32_t(k.cell[2])) * 0x165667B19E3779F9ull;
  x ^= (x >> 27) + uint64_t(uint32_t(k.normal)) * 0x27D4EB2F165667C5ull;
  x ^= (x >> 33) + uint64_t(uint32_t(k.plane)) * 0x94D049BB133111EBull;
  return size_t(x ^ (x >> 32)) & ((size_t(1) << bits) - 1);
}

// floor(v), clamped to int32's range (the key of a point far outside any scene is still a key).
int32_t floor_index(float v) {
  constexpr float kLimit = 2.0e9f;
  return int32_t(std::floor(std::fmax(-kLimit, std::fmin(kLimit, std::isfinite(v) ? v : 0.f))));
}

}  // namespace

float3 BakeFileProbeField::irradiance(const float3& p, const float3& n) const {
  loader::Rgb e;
  file_.sample_ddgi(loader::Vec3{p.x, p.y, p.z}, loader::Vec3{n.x, n.y, n.z}, e, loader::SampleOptions{});
  return float3{e[0], e[1], e[2]};
}

CachedProbeField::CachedProbeField(const ProbeField& field, float cell, int table_bits)
    : field_(field), cell_(cell), table_bits_(std::clamp(table_bits, 1, 30)) {}

int CachedProbeField::table_bits_for(uint32_t threads) {
  constexpr uint64_t kAllTables = uint64_t(256) << 20;
  constexpr int kMostBits = 20, kLeastBits = 16;
  int bits = kMostBits;
  while (bits > kLeastBits && uint64_t(std::max(1u, threads)) * table_bytes(bits) > kAllTables) --bits;
  return bits;
}

uint64_t CachedProbeField::table_bytes(int bits) { return (uint64_t(1) << bits) * sizeof(Slot); }

bool CachedProbeField::used() const {
  for (const std::vector<Slot>& table : tables_)
    if (!table.empty()) return true;
  return false;
}

CachedProbeField::Key CachedProbeField::key_of(const float3& p, const float3& n) const {
  Key k;
  int tx = 0, ty = 0;
  kernels::oct_texel_of(n, kNormalBins, tx, ty);
  k.normal = ty * kNormalBins + tx;
  const float3 axis = kernels::oct_texel_direction(tx, ty, kNormalBins);
  k.cell[0] = floor_index(p.x / cell_);
  k.cell[1] = floor_index(p.y / cell_);
  k.cell[2] = floor_index(p.z / cell_);
  k.plane = floor_index(kernels::dot(p, axis) * (float(kPlaneSteps) / cell_));
  return k;
}

void CachedProbeField::read_at(const Key& k, float3& p, float3& n) const {
  n = kernels::oct_texel_direction(k.normal % kNormalBins, k.normal / kNormalBins, kNormalBins);
  const float3 centre{(float(k.cell[0]) + 0.5f) * cell_, (float(k.cell[1]) + 0.5f) * cell_,
                      (float(k.cell[2]) + 0.5f) * cell_};
  const float plane = (float(k.plane) + 0.5f) * (cell_ / float(kPlaneSteps));
  p = centre - n * (kernels::dot(centre, n) - plane);
}

float3 CachedProbeField::irradiance(const float3& p, const float3& n) const {
  const Key k = key_of(p, n);
  std::vector<Slot>& table = tables_.local();
  if (table.empty()) table.resize(size_t(1) << table_bits_);
  Slot& slot = table[slot_of(k, table_bits_)];
  if (!(slot.key == k)) {
    float3 at, normal;
    read_at(k, at, normal);
    slot.key = k;
    slot.value = field_.irradiance(at, normal);
  }
  return slot.value;
}

}  // namespace gibake
