// DDGI volumes: grouping sections into volumes, consistency checks and typed element access.
#include <cmath>
#include <cstring>
#include <new>

#include "gibake/loader.hpp"

namespace gibake::loader {
namespace {

Error fail(ErrorCode code, std::string message) { return Error{code, std::move(message)}; }

template <typename T>
T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

float load_f(const uint8_t* base, uint32_t format16, uint32_t format, size_t index) {
  if (format == format16) return half_to_float(load<uint16_t>(base + index * 2));
  return load<float>(base + index * 4);
}

bool finite3(const float* v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

// k of the atlas layout; version 1.0 files leave the field 0, meaning all Y planes in one band.
uint32_t planes_per_row(const gibake_ddgi_volume& d) {
  return d.atlas_planes_per_row ? d.atlas_planes_per_row : uint32_t(d.counts[1]);
}

bool is_sparse(const gibake_ddgi_volume& d) { return (d.flags & GIBAKE_DDGI_FLAG_SPARSE) != 0; }

// Tiles across and down an atlas: the grid's layout, or a sparse volume's slots in rows of T.
std::array<uint64_t, 2> atlas_tiles(const gibake_ddgi_volume& d) {
  if (is_sparse(d)) {
    const uint64_t t = d.atlas_tiles_per_row;
    return {t, (uint64_t(d.stored_probes) + t - 1) / t};
  }
  const uint64_t k = planes_per_row(d);
  return {uint64_t(d.counts[0]) * k, uint64_t(d.counts[2]) * ((uint64_t(d.counts[1]) + k - 1) / k)};
}

Error check_atlas(const gibake_ddgi_volume& d, uint32_t tile, uint32_t width, uint32_t height,
                  const char* what) {
  if (width == 0 && height == 0) return {};
  if (tile == 0 || tile > 256 || d.tile_border > 8)
    return fail(ErrorCode::BadVolume, std::string(what) + " atlas: tile size out of range");
  const uint64_t k = planes_per_row(d);
  if (!is_sparse(d) && k > uint64_t(d.counts[1]))
    return fail(ErrorCode::BadVolume, "atlas_planes_per_row " + std::to_string(k) + " exceeds Y");
  const uint64_t side = tile + 2ull * d.tile_border;
  const std::array<uint64_t, 2> tiles = atlas_tiles(d);
  const uint64_t w = tiles[0] * side, h = tiles[1] * side;
  if (w != width || h != height)
    return fail(ErrorCode::BadVolume, std::string(what) + " atlas is " + std::to_string(width) + "x" +
                                          std::to_string(height) + ", layout needs " + std::to_string(w) +
                                          "x" + std::to_string(h));
  return {};
}

Error check_sparse(const gibake_ddgi_volume& d) {
  if (d.flags & ~GIBAKE_DDGI_FLAG_SPARSE) return fail(ErrorCode::BadVolume, "unknown flags " + std::to_string(d.flags));
  if (!is_sparse(d)) return {};  // stored_probes and atlas_tiles_per_row were reserved words: unread
  if (d.stored_probes < 1 || d.stored_probes > d.probe_count)
    return fail(ErrorCode::BadVolume,
                "stored_probes " + std::to_string(d.stored_probes) + " not in 1.." + std::to_string(d.probe_count));
  if (d.atlas_tiles_per_row < 1 || d.atlas_tiles_per_row > d.stored_probes || d.atlas_planes_per_row != 0)
    return fail(ErrorCode::BadVolume, "atlas_tiles_per_row must be in 1..stored_probes and atlas_planes_per_row 0");
  return {};
}

Error check_desc(const gibake_ddgi_volume& d) {
  uint64_t product = 1;
  for (int i = 0; i < 3; ++i) {
    if (d.counts[i] < 1 || d.counts[i] > (1 << 16))
      return fail(ErrorCode::BadVolume, "probe count on axis " + std::to_string(i) + " out of range");
    product *= uint64_t(d.counts[i]);
  }
  if (product > (1ull << 26) || product != d.probe_count)
    return fail(ErrorCode::BadVolume, "probe_count " + std::to_string(d.probe_count) +
                                          " != product of counts " + std::to_string(product));
  if ((d.sh_order != 1 && d.sh_order != 2) || d.sh_coefficients != (d.sh_order + 1) * (d.sh_order + 1))
    return fail(ErrorCode::BadVolume, "sh_order/sh_coefficients invalid");
  if (!finite3(d.grid_min) || !finite3(d.grid_max) || !finite3(d.spacing) || !std::isfinite(d.max_distance))
    return fail(ErrorCode::BadVolume, "non-finite grid bounds or spacing");
  for (int i = 0; i < 3; ++i)
    if (d.spacing[i] < 0.f || (d.counts[i] > 1 && !(d.spacing[i] > 0.f)))
      return fail(ErrorCode::BadVolume, "spacing on axis " + std::to_string(i) + " invalid");
  if (Error e = check_sparse(d)) return e;
  if (Error e = check_atlas(d, d.irradiance_tile, d.irradiance_width, d.irradiance_height, "irradiance")) return e;
  return check_atlas(d, d.depth_tile, d.depth_width, d.depth_height, "depth");
}

// Probes with an element in the per-probe sections.
uint64_t stored(const gibake_ddgi_volume& d) { return is_sparse(d) ? d.stored_probes : d.probe_count; }

uint64_t expected_count(const gibake_ddgi_volume& d, uint32_t type) {
  switch (type) {
    case GIBAKE_SECTION_DDGI_SH:
      return stored(d) * d.sh_coefficients * 3;
    case GIBAKE_SECTION_DDGI_IRRADIANCE: return uint64_t(d.irradiance_width) * d.irradiance_height;
    case GIBAKE_SECTION_DDGI_DEPTH: return uint64_t(d.depth_width) * d.depth_height;
    case GIBAKE_SECTION_DDGI_PROBE_SLOTS:
      return d.probe_count;
    default:
      return stored(d);
  }
}

bool is_ddgi_data(uint32_t type) {
  return (type >= GIBAKE_SECTION_DDGI_SH && type <= GIBAKE_SECTION_DDGI_DEPTH) ||
         type == GIBAKE_SECTION_DDGI_PROBE_SLOTS;
}

// A sparse volume's slots: assigned in probe-index order (so each slot once), every one below
// stored_probes, and stored_probes of them. One pass, no memory: hostile files stay cheap.
Error check_slots(const DdgiVolume& v, const std::string& label) {
  uint64_t next = 0;
  for (uint32_t p = 0; p < v.probe_count(); ++p) {
    const uint32_t s = v.slot(p);
    if (s == GIBAKE_PROBE_SLOT_NONE) continue;
    if (s != next)
      return fail(ErrorCode::BadVolume, label + ": probe " + std::to_string(p) + " has slot " + std::to_string(s) +
                                            ", the slots in probe order need " + std::to_string(next));
    ++next;
  }
  if (next != v.stored_probes())
    return fail(ErrorCode::BadVolume, label + ": " + std::to_string(next) + " probes have a slot, stored_probes is " +
                                          std::to_string(v.stored_probes()));
  return {};
}

}  // namespace

Error BakeFile::build_volumes() {
  for (uint32_t i = 0; i < sections_.size(); ++i) {
    const gibake_section_entry& s = sections_[i];
    if (s.type == GIBAKE_SECTION_METADATA) {
      if (metadata_section_ >= 0) return fail(ErrorCode::DuplicateSection, "two metadata sections");
      metadata_section_ = int(i);
    }
    if (s.type != GIBAKE_SECTION_DDGI_VOLUME) continue;
    if (s.count != 1) return fail(ErrorCode::BadVolume, "section " + std::to_string(i) + " (ddgi_volume): count != 1");
    DdgiVolume v;
    std::memcpy(&v.desc_, data_ + s.offset, sizeof v.desc_);
    v.volume_section_ = i;
    if (Error e = check_desc(v.desc_)) {
      e.message = "section " + std::to_string(i) + " (ddgi_volume): " + e.message;
      return e;
    }
    volumes_.push_back(v);
  }
  std::vector<int64_t> volume_of_section(sections_.size(), -1);  // linear, even for huge tables
  for (size_t v = 0; v < volumes_.size(); ++v) volume_of_section[volumes_[v].volume_section_] = int64_t(v);
  for (uint32_t i = 0; i < sections_.size(); ++i) {
    if (!is_ddgi_data(sections_[i].type)) continue;
    const uint32_t group = sections_[i].group;
    DdgiVolume* owner = group < volume_of_section.size() && volume_of_section[group] >= 0
                            ? &volumes_[size_t(volume_of_section[group])]
                            : nullptr;
    if (!owner)
      return fail(ErrorCode::BadVolume, "section " + std::to_string(i) + " (" + section_type_name(sections_[i].type) +
                                            "): group " + std::to_string(sections_[i].group) + " is not a ddgi_volume section");
    if (Error e = attach(*owner, i)) return e;
  }
  for (const DdgiVolume& v : volumes_) {
    const std::string label = "volume section " + std::to_string(v.volume_section_);
    if (!v.sh_.data) return fail(ErrorCode::MissingSection, label + ": no ddgi_sh section");
    if (v.desc_.irradiance_width && !v.irradiance_.data)
      return fail(ErrorCode::MissingSection, label + ": no ddgi_irradiance section");
    if (v.desc_.depth_width && !v.depth_.data)
      return fail(ErrorCode::MissingSection, label + ": no ddgi_depth section");
    if (v.sparse() && !v.slots_.data)
      return fail(ErrorCode::MissingSection, label + ": sparse, no ddgi_probe_slots section");
    if (v.sparse())
      if (Error e = check_slots(v, label)) return e;
  }
  return {};
}

Error BakeFile::attach(DdgiVolume& v, uint32_t index) {
  const gibake_section_entry& s = sections_[index];
  const std::string label = "section " + std::to_string(index) + " (" + section_type_name(s.type) + ")";
  DdgiVolume::View* view = nullptr;
  switch (s.type) {
    case GIBAKE_SECTION_DDGI_SH: view = &v.sh_; break;
    case GIBAKE_SECTION_DDGI_OFFSETS: view = &v.offsets_; break;
    case GIBAKE_SECTION_DDGI_STATES: view = &v.states_; break;
    case GIBAKE_SECTION_DDGI_STATS: view = &v.stats_; break;
    case GIBAKE_SECTION_DDGI_IRRADIANCE: view = &v.irradiance_; break;
    case GIBAKE_SECTION_DDGI_PROBE_SLOTS:
      view = &v.slots_;
      break;
    default: view = &v.depth_; break;
  }
  if (s.type == GIBAKE_SECTION_DDGI_PROBE_SLOTS && !v.sparse())
    return fail(ErrorCode::BadVolume, label + ": the volume is not sparse");
  if (s.format == GIBAKE_FORMAT_RGB9E5 && !(std::isfinite(v.desc_.irradiance_scale) && v.desc_.irradiance_scale > 0.f))
    return fail(ErrorCode::BadVolume, label + ": RGB9E5 texels need an irradiance_scale > 0");
  if (view->data) return fail(ErrorCode::DuplicateSection, label + ": second section of this type for the volume");
  const uint64_t expected = expected_count(v.desc_, s.type);
  if (s.count != expected || expected == 0)
    return fail(ErrorCode::BadVolume, label + ": count " + std::to_string(s.count) + ", volume needs " +
                                          std::to_string(expected));
  view->data = data_ + s.offset;
  view->format = s.format;
  view->section = index;
  return {};
}

uint32_t DdgiVolume::slot(uint32_t probe) const {
  if (probe >= desc_.probe_count) return GIBAKE_PROBE_SLOT_NONE;
  if (!sparse()) return probe;
  return slots_.data ? load<uint32_t>(slots_.data + size_t(probe) * 4) : GIBAKE_PROBE_SLOT_NONE;
}

float DdgiVolume::sh(uint32_t probe, uint32_t coefficient, uint32_t channel) const {
  const uint32_t at = slot(probe);
  if (at == GIBAKE_PROBE_SLOT_NONE || coefficient >= desc_.sh_coefficients || channel >= 3) return 0.f;
  const size_t i = (size_t(at) * desc_.sh_coefficients + coefficient) * 3 + channel;
  return load_f(sh_.data, GIBAKE_FORMAT_F16, sh_.format, i);
}

void DdgiVolume::sh_probe(uint32_t probe, float* out) const {
  for (uint32_t c = 0; c < desc_.sh_coefficients; ++c)
    for (uint32_t k = 0; k < 3; ++k) out[c * 3 + k] = sh(probe, c, k);
}

Vec3 DdgiVolume::offset(uint32_t probe) const {
  const uint32_t at = slot(probe);
  if (!offsets_.data || at == GIBAKE_PROBE_SLOT_NONE) return {0.f, 0.f, 0.f};
  return load<Vec3>(offsets_.data + size_t(at) * 12);
}

uint32_t DdgiVolume::state(uint32_t probe) const {
  const uint32_t at = slot(probe);
  if (at == GIBAKE_PROBE_SLOT_NONE && sparse()) return GIBAKE_PROBE_INACTIVE;
  if (!states_.data || at == GIBAKE_PROBE_SLOT_NONE) return GIBAKE_PROBE_ACTIVE;
  if (states_.format == GIBAKE_FORMAT_U8) return states_.data[at];
  return load<uint32_t>(states_.data + size_t(at) * 4);
}

gibake_probe_stats DdgiVolume::stats(uint32_t probe) const {
  const uint32_t at = slot(probe);
  if (!stats_.data || at == GIBAKE_PROBE_SLOT_NONE) return gibake_probe_stats{};
  return load<gibake_probe_stats>(stats_.data + size_t(at) * sizeof(gibake_probe_stats));
}

std::array<float, 4> DdgiVolume::irradiance_texel(uint32_t x, uint32_t y) const {
  std::array<float, 4> out{0.f, 0.f, 0.f, 0.f};
  if (!irradiance_.data || x >= desc_.irradiance_width || y >= desc_.irradiance_height) return out;
  const size_t texel = size_t(y) * desc_.irradiance_width + x;
  if (irradiance_.format == GIBAKE_FORMAT_RGB9E5) {
    const std::array<float, 3> rgb = rgb9e5_to_float(load<uint32_t>(irradiance_.data + texel * 4));
    const float s = desc_.irradiance_scale;
    return {rgb[0] * s, rgb[1] * s, rgb[2] * s, 1.f};
  }
  for (size_t k = 0; k < 4; ++k)
    out[k] = load_f(irradiance_.data, GIBAKE_FORMAT_RGBA16F, irradiance_.format, texel * 4 + k);
  return out;
}

std::array<float, 2> DdgiVolume::depth_texel(uint32_t x, uint32_t y) const {
  std::array<float, 2> out{0.f, 0.f};
  if (!depth_.data || x >= desc_.depth_width || y >= desc_.depth_height) return out;
  const size_t base = (size_t(y) * desc_.depth_width + x) * 2;
  for (size_t k = 0; k < 2; ++k) out[k] = load_f(depth_.data, GIBAKE_FORMAT_RG16F, depth_.format, base + k);
  return out;
}

uint32_t DdgiVolume::atlas_planes_per_row() const { return planes_per_row(desc_); }

namespace {

// Bytes of one element of an atlas format: 2 for the binary16 formats, else 4.
uint32_t element_bytes(uint32_t format, uint32_t format16) { return format == format16 ? 2u : 4u; }

// Copies each probe's tile (border included) of an atlas of `channels`-element texels, the first
// `kept` elements of each, into `out` at the probe's block (none: a probe without one).
void copy_tiles(const DdgiVolume& v, const uint8_t* atlas, uint32_t atlas_width, uint32_t interior, uint32_t channels,
                uint32_t kept, uint32_t bytes, const std::vector<uint32_t>& block, std::vector<uint8_t>& out,
                uint32_t blocks, uint32_t none) {
  const uint32_t side = interior + 2 * v.desc().tile_border;
  const size_t texel_bytes = size_t(kept) * bytes, block_bytes = size_t(side) * side * texel_bytes;
  out.resize(block_bytes * blocks);
  for (uint32_t probe = 0; probe < block.size(); ++probe) {
    if (block[probe] == none) continue;
    const std::array<uint32_t, 2> origin = v.tile_origin(probe, interior);
    uint8_t* to = out.data() + block_bytes * block[probe];
    for (uint32_t y = 0; y < side; ++y)
      for (uint32_t x = 0; x < side; ++x, to += texel_bytes) {
        const size_t texel = size_t(origin[1] + y) * atlas_width + origin[0] + x;
        std::memcpy(to, atlas + texel * channels * bytes, texel_bytes);
      }
  }
}

// copy_tiles for an RGB9E5 irradiance atlas: each texel decoded to three float32 values.
void decode_rgb9e5_tiles(const DdgiVolume& v, const std::vector<uint32_t>& block, std::vector<uint8_t>& out,
                         uint32_t blocks, uint32_t none) {
  const gibake_ddgi_volume& d = v.desc();
  const uint32_t side = d.irradiance_tile + 2 * d.tile_border;
  const size_t block_bytes = size_t(side) * side * 12;
  out.resize(block_bytes * blocks);
  for (uint32_t probe = 0; probe < block.size(); ++probe) {
    if (block[probe] == none) continue;
    const std::array<uint32_t, 2> origin = v.tile_origin(probe, d.irradiance_tile);
    uint8_t* to = out.data() + block_bytes * block[probe];
    for (uint32_t y = 0; y < side; ++y)
      for (uint32_t x = 0; x < side; ++x, to += 12) {
        const std::array<float, 4> t = v.irradiance_texel(origin[0] + x, origin[1] + y);
        std::memcpy(to, t.data(), 12);
      }
  }
}

}  // namespace

void DdgiVolume::build_probe_tiles(ProbeTiles& tiles) const {
  uint32_t blocks = 0;
  tiles.block.assign(desc_.probe_count, ProbeTiles::kNone);
  for (uint32_t p = 0; p < desc_.probe_count; ++p)
    if (state(p) != GIBAKE_PROBE_INACTIVE) tiles.block[p] = blocks++;  // the sampler skips inactive probes
  if (depth_.data) {
    tiles.depth_bytes = element_bytes(depth_.format, GIBAKE_FORMAT_RG16F);
    copy_tiles(*this, depth_.data, desc_.depth_width, desc_.depth_tile, 2, 2, tiles.depth_bytes, tiles.block,
               tiles.depth, blocks, ProbeTiles::kNone);
  }
  if (irradiance_.data && irradiance_.format == GIBAKE_FORMAT_RGB9E5) {
    tiles.irradiance_bytes = 4;  // decoded to float32 (exact)
    decode_rgb9e5_tiles(*this, tiles.block, tiles.irradiance, blocks, ProbeTiles::kNone);
  } else if (irradiance_.data) {
    tiles.irradiance_bytes = element_bytes(irradiance_.format, GIBAKE_FORMAT_RGBA16F);
    copy_tiles(*this, irradiance_.data, desc_.irradiance_width, desc_.irradiance_tile, 4, 3, tiles.irradiance_bytes,
               tiles.block, tiles.irradiance, blocks, ProbeTiles::kNone);
  }
}

const uint8_t* DdgiVolume::probe_tile(uint32_t probe, bool depth) const {
  if (!tiles_ || probe >= tiles_->block.size() || tiles_->block[probe] == ProbeTiles::kNone) return nullptr;
  const std::vector<uint8_t>& data = depth ? tiles_->depth : tiles_->irradiance;
  if (data.empty()) return nullptr;
  const size_t side = (depth ? desc_.depth_tile : desc_.irradiance_tile) + 2 * desc_.tile_border;
  const size_t texel_bytes = depth ? 2 * tiles_->depth_bytes : 3 * tiles_->irradiance_bytes;
  return data.data() + side * side * texel_bytes * tiles_->block[probe];
}

uint32_t DdgiVolume::probe_tile_element_bytes(bool depth) const {
  return tiles_ ? (depth ? tiles_->depth_bytes : tiles_->irradiance_bytes) : 0;
}

size_t DdgiVolume::probe_tile_bytes() const {
  if (!tiles_) return 0;
  return tiles_->block.size() * sizeof(uint32_t) + tiles_->depth.size() + tiles_->irradiance.size();
}

void BakeFile::build_probe_tiles() {
  // A failed allocation leaves the sampler on the atlases: the same answers, only slower.
  try {
    for (DdgiVolume& v : volumes_) {
      tiles_.push_back(std::make_unique<DdgiVolume::ProbeTiles>());
      v.build_probe_tiles(*tiles_.back());
      v.tiles_ = tiles_.back().get();
    }
  } catch (const std::bad_alloc&) {
    for (DdgiVolume& v : volumes_) v.tiles_ = nullptr;
    tiles_.clear();
  }
}

std::array<uint32_t, 2> DdgiVolume::tile_cell(const std::array<int32_t, 3>& c) const {
  if (sparse()) {
    const uint32_t t = desc_.atlas_tiles_per_row;
    const uint32_t at = slot(uint32_t(c[0]) +
                             uint32_t(desc_.counts[0]) * (uint32_t(c[1]) + uint32_t(desc_.counts[1]) * uint32_t(c[2])));
    if (at == GIBAKE_PROBE_SLOT_NONE) return {t, 0};  // beyond the atlas: texel reads give zeros
    return {at % t, at / t};
  }
  const uint32_t k = atlas_planes_per_row();
  return {uint32_t(c[0]) + uint32_t(desc_.counts[0]) * (uint32_t(c[1]) % k),
          uint32_t(c[2]) + uint32_t(desc_.counts[2]) * (uint32_t(c[1]) / k)};
}

std::array<uint32_t, 2> DdgiVolume::tile_origin(uint32_t probe, uint32_t interior) const {
  const std::array<uint32_t, 2> cell = tile_cell(probe_coord(probe));
  const uint32_t side = interior + 2 * desc_.tile_border;
  return {cell[0] * side, cell[1] * side};
}

std::array<int32_t, 3> DdgiVolume::probe_coord(uint32_t index) const {
  const int32_t x = int32_t(index % uint32_t(desc_.counts[0]));
  const uint32_t rest = index / uint32_t(desc_.counts[0]);
  return {x, int32_t(rest % uint32_t(desc_.counts[1])), int32_t(rest / uint32_t(desc_.counts[1]))};
}

Vec3 DdgiVolume::probe_rest_position(const std::array<int32_t, 3>& c) const {
  return {desc_.grid_min[0] + float(c[0]) * desc_.spacing[0], desc_.grid_min[1] + float(c[1]) * desc_.spacing[1],
          desc_.grid_min[2] + float(c[2]) * desc_.spacing[2]};
}

Vec3 DdgiVolume::probe_position(uint32_t index) const {
  Vec3 p = probe_rest_position(probe_coord(index));
  const Vec3 o = offset(index);
  return {p[0] + o[0], p[1] + o[1], p[2] + o[2]};
}

}  // namespace gibake::loader
