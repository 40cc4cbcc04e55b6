// Bake file writer: header + section table + 16-aligned sections (gibake/format.h).
#include "io/bakefile/bake_file.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>
#include <xxhash.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <utility>

#include "gibake/format.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_stream.h"
#include "io/bakefile/bake_verify.h"
#include "io/bakefile/half_encode.h"
#include "io/bakefile/sparse_volume.h"
#include "io/bakefile/vxgi_sections.h"
#include "io/output/bake_atomic.h"
#include "io/timer.h"

#ifndef GIBAKE_VERSION
#define GIBAKE_VERSION "0.1.0"
#endif

namespace gibake {
namespace {

// A section before it is laid out: its payload as given (`bytes`), or float values encoded straight
// into the file buffer (f32, or f16 when `half`), so that large payloads are never copied twice.
struct PendingSection {
  uint32_t type = 0, format = 0, group = 0;
  uint64_t count = 0;
  std::vector<uint8_t> bytes;
  const std::vector<float>* floats = nullptr;
  bool half = false;
  uint64_t given_size = 0;  // a section predicted from its size alone (predict_ddgi_table)
  bool streamed = false;    // encoded, checksummed and written by a BakeFileStream already
  uint64_t checksum = 0;    // a streamed section's
  uint64_t size() const {
    if (floats) return uint64_t(floats->size()) * (half ? 2 : 4);
    return given_size ? given_size : bytes.size();
  }
};

PendingSection float_section(uint32_t type, uint32_t format, uint32_t group, uint64_t count,
                             const std::vector<float>& values, bool half) {
  PendingSection s{type, format, group, count, {}};
  s.floats = &values;
  s.half = half;
  return s;
}

template <typename T>
void append(std::vector<uint8_t>& out, const T& value) {
  const size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &value, sizeof(T));
}

// Payloads run to millions of values: converted and scanned in fixed chunks, in parallel (each
// output value depends on its input only, so the bytes never depend on the thread count).
constexpr size_t kChunkValues = size_t(1) << 16;

template <class F>
void for_chunks(size_t n, F&& f) {
  const size_t chunks = (n + kChunkValues - 1) / kChunkValues;
  auto run = [&](size_t c) { f(c * kChunkValues, std::min(n, (c + 1) * kChunkValues)); };
  if (chunks < 2) {
    for (size_t c = 0; c < chunks; ++c) run(c);
    return;
  }
  tbb::parallel_for(size_t(0), chunks, run);
}

bool fits_half(const std::vector<float>& values, tbb::task_arena* arena) {
  std::atomic<bool> fits{true};
  arena->execute([&] {
    for_chunks(values.size(), [&](size_t first, size_t last) {
      if (fits.load(std::memory_order_relaxed) && any_beyond_half(values.data() + first, last - first)) fits = false;
    });
  });
  return fits;
}

bool use_half(FloatPrecision precision, const std::vector<float>& values, tbb::task_arena* arena) {
  if (precision == FloatPrecision::Auto || precision == FloatPrecision::SharedExponent) return fits_half(values, arena);
  return precision == FloatPrecision::Half;
}

// A float section stored as float16 or float32 as `precision` decides for these values; `per`
// floats make one element (its count).
PendingSection precision_section(uint32_t type, uint32_t half_format, uint32_t full_format, uint32_t group,
                                 size_t per, const std::vector<float>& values, FloatPrecision precision,
                                 tbb::task_arena* arena) {
  const bool half = use_half(precision, values, arena);
  return float_section(type, half ? half_format : full_format, group, values.size() / per, values, half);
}

// Encodes or copies one section's payload to `dst` (its size() bytes); the values clamped to the
// float16 range are counted into `clamped`. Call inside the writer's arena.
void fill_payload(const PendingSection& s, uint8_t* dst, std::atomic<size_t>& clamped) {
  if (!s.floats) {
    if (!s.bytes.empty()) std::memcpy(dst, s.bytes.data(), s.bytes.size());
    return;
  }
  const float* v = s.floats->data();
  const size_t bytes_per = s.half ? 2 : 4;
  for_chunks(s.floats->size(), [&](size_t first, size_t last) {
    if (s.half)
      clamped += encode_half(v + first, last - first, dst + first * bytes_per);
    else
      std::memcpy(dst + first * bytes_per, v + first, (last - first) * bytes_per);
  });
}

// The largest RGB value of an RGBA atlas (alpha is always 1), or -1 when a value is negative or not
// finite: RGB9E5 cannot hold those.
float rgb9e5_range(const std::vector<float>& rgba, tbb::task_arena* arena) {
  const size_t texels = rgba.size() / 4, chunks = (texels + kChunkValues - 1) / kChunkValues;
  std::vector<float> largest(chunks, 0.f);  // per chunk: the maximum is the same in any order
  arena->execute([&] {
    for_chunks(texels, [&](size_t first, size_t last) {
      float m = 0.f;
      for (size_t t = first; t < last; ++t)
        for (size_t k = 0; k < 3; ++k) {
          const float v = rgba[t * 4 + k];
          m = v >= 0.f && v <= 3.0e38f ? std::max(m, v) : std::numeric_limits<float>::infinity();
        }
      largest[first / kChunkValues] = m;
    });
  });
  const float m = largest.empty() ? 0.f : *std::max_element(largest.begin(), largest.end());
  return std::isfinite(m) ? m : -1.f;
}

// The irradiance atlas's section: RGB9E5 when asked for and every value can be held, its texels
// scaled by 1 / `scale` (a power of two, at least 1, so that the largest fits 65408: sunlight
// passes it), else as `precision` says (Auto's choice for SharedExponent; `scale` stays 0).
PendingSection irradiance_section(const std::vector<float>& rgba, FloatPrecision precision, uint32_t group,
                                  tbb::task_arena* arena, float& scale) {
  scale = 0.f;
  const float largest = precision == FloatPrecision::SharedExponent ? rgb9e5_range(rgba, arena) : -1.f;
  if (largest < 0.f)
    return precision_section(GIBAKE_SECTION_DDGI_IRRADIANCE, GIBAKE_FORMAT_RGBA16F, GIBAKE_FORMAT_RGBA32F, group, 4,
                             rgba, precision, arena);
  scale = 1.f;
  while (largest / scale > loader::kRgb9e5Max) scale *= 2.f;
  const float inverse = 1.f / scale;  // exact: a power of two
  const size_t texels = rgba.size() / 4;
  PendingSection s{GIBAKE_SECTION_DDGI_IRRADIANCE, GIBAKE_FORMAT_RGB9E5, group, texels, {}};
  s.bytes.resize(texels * 4);
  arena->execute([&] {
    for_chunks(texels, [&](size_t first, size_t last) {
      for (size_t t = first; t < last; ++t) {
        const uint32_t packed =
            loader::float_to_rgb9e5(rgba[t * 4] * inverse, rgba[t * 4 + 1] * inverse, rgba[t * 4 + 2] * inverse);
        std::memcpy(s.bytes.data() + t * 4, &packed, 4);
      }
    });
  });
  return s;
}

gibake_ddgi_volume make_volume_desc(const DdgiResult& r) {
  gibake_ddgi_volume d = ddgi_volume_record(r.desc);
  if (!r.irradiance_atlas.empty()) {
    d.irradiance_width = uint32_t(r.irradiance_width);
    d.irradiance_height = uint32_t(r.irradiance_height);
  }
  if (!r.depth_atlas.empty()) {
    d.depth_width = uint32_t(r.depth_width);
    d.depth_height = uint32_t(r.depth_height);
    d.depth_tile = uint32_t(r.depth_tile);
  }
  d.atlas_planes_per_row = uint32_t(r.atlas_planes_per_row > 0 ? r.atlas_planes_per_row : r.desc.counts[1]);
  return d;
}

Status check_ddgi(const DdgiResult& r) {
  const size_t probes = size_t(std::max(0, r.desc.probe_count()));
  auto bad = [](const std::string& what) { return Status::invalid("", "ddgi result", what); };
  for (int i = 0; i < 3; ++i)
    if (r.desc.counts[i] < 1) return bad("probe counts must be >= 1");
  if (r.desc.sh_order != 1 && r.desc.sh_order != 2) return bad("sh_order must be 1 or 2");
  if (probes == 0) return bad("no probes");
  if (r.sh.size() != probes * size_t(r.desc.sh_coefficients()) * 3) return bad("sh size does not match the probe count");
  if (!r.offsets.empty() && r.offsets.size() != probes * 3) return bad("offsets size does not match the probe count");
  if (!r.states.empty() && r.states.size() != probes) return bad("states size does not match the probe count");
  if (!r.stats.empty() && r.stats.size() != probes) return bad("stats size does not match the probe count");
  if (r.atlas_planes_per_row < 0 || r.atlas_planes_per_row > r.desc.counts[1])
    return bad("atlas_planes_per_row must be between 1 and the Y probe count (0: Y)");
  if (!r.irradiance_atlas.empty() &&
      r.irradiance_atlas.size() != size_t(r.irradiance_width) * size_t(r.irradiance_height) * 4)
    return bad("irradiance atlas size does not match its width and height");
  if (r.depth_tile < 1 || r.depth_tile > kDepthTexels)
    return bad("depth_tile must be between 1 and " + std::to_string(kDepthTexels));
  if (!r.depth_atlas.empty() && r.depth_atlas.size() != size_t(r.depth_width) * size_t(r.depth_height) * 2)
    return bad("depth atlas size does not match its width and height");
  return Status::ok();
}

// `sparse` (optional): the volume's stored probes, written instead of `r` with its slot map.
void add_ddgi_sections(const DdgiResult& grid, const BakeFileOptions& o, uint32_t group,
                       std::vector<PendingSection>& out, tbb::task_arena* arena, const SparseVolume* sparse) {
  const DdgiResult& r = sparse ? sparse->result : grid;
  gibake_ddgi_volume desc = make_volume_desc(r);
  if (sparse) {
    desc.flags |= GIBAKE_DDGI_FLAG_SPARSE;
    desc.stored_probes = sparse->stored;
    desc.atlas_tiles_per_row = sparse->tiles_per_row;
    desc.atlas_planes_per_row = 0;
  }
  PendingSection irradiance;
  if (!r.irradiance_atlas.empty())
    irradiance = irradiance_section(r.irradiance_atlas, o.atlas, group, arena, desc.irradiance_scale);
  PendingSection volume{GIBAKE_SECTION_DDGI_VOLUME, GIBAKE_FORMAT_STRUCT, group, 1, {}};
  append(volume.bytes, desc);
  out.push_back(std::move(volume));
  out.push_back(precision_section(GIBAKE_SECTION_DDGI_SH, GIBAKE_FORMAT_F16, GIBAKE_FORMAT_F32, group, 1, r.sh, o.sh,
                                  arena));
  if (!r.offsets.empty())
    out.push_back(float_section(GIBAKE_SECTION_DDGI_OFFSETS, GIBAKE_FORMAT_F32X3, group, r.offsets.size() / 3,
                                r.offsets, false));
  if (!r.states.empty()) {
    PendingSection s{GIBAKE_SECTION_DDGI_STATES, GIBAKE_FORMAT_U8, group, r.states.size(), {}};
    for (ProbeState state : r.states) s.bytes.push_back(static_cast<uint8_t>(state));
    out.push_back(std::move(s));
  }
  if (!r.stats.empty()) {
    PendingSection s{GIBAKE_SECTION_DDGI_STATS, GIBAKE_FORMAT_PROBE_STATS, group, r.stats.size(), {}};
    for (const DdgiProbeStats& st : r.stats)
      append(s.bytes, gibake_probe_stats{st.rays, st.relative_error, st.nearest_front, st.backface_fraction});
    out.push_back(std::move(s));
  }
  if (!r.irradiance_atlas.empty()) out.push_back(std::move(irradiance));
  if (!r.depth_atlas.empty())
    out.push_back(precision_section(GIBAKE_SECTION_DDGI_DEPTH, GIBAKE_FORMAT_RG16F, GIBAKE_FORMAT_RG32F, group, 2,
                                    r.depth_atlas, o.atlas, arena));
  if (sparse) {
    PendingSection slots{GIBAKE_SECTION_DDGI_PROBE_SLOTS, GIBAKE_FORMAT_U32, group, sparse->slots.size(), {}};
    slots.bytes.resize(sparse->slots.size() * 4);
    std::memcpy(slots.bytes.data(), sparse->slots.data(), slots.bytes.size());
    out.push_back(std::move(slots));
  }
}

Status check_lpv(const LpvResult& r) {
  auto bad = [](const std::string& what) { return Status::invalid("", "lpv result", what); };
  if (r.cascades.empty() || r.cascades.size() > 64) return bad("between 1 and 64 cascades expected");
  for (const LpvCascade& c : r.cascades) {
    for (int a = 0; a < 3; ++a)
      if (c.dims[a] < 1) return bad("cell counts must be >= 1");
    if (!(c.cell_size > 0.f) || !std::isfinite(c.cell_size)) return bad("cell size must be positive");
    if (c.sh.size() != c.cell_count() * 12) return bad("sh size does not match the cell count");
  }
  return Status::ok();
}

void add_lpv_sections(const LpvResult& r, const BakeFileOptions& o, std::vector<PendingSection>& out,
                      tbb::task_arena* arena) {
  for (size_t k = 0; k < r.cascades.size(); ++k) {
    const LpvCascade& c = r.cascades[k];
    gibake_lpv_cascade d{};
    for (int a = 0; a < 3; ++a) {
      d.grid_min[a] = c.grid_min[a];
      d.dims[a] = c.dims[a];
    }
    d.cell_size = c.cell_size;
    d.cell_count = uint32_t(c.cell_count());
    d.cascade_index = uint32_t(k);
    d.cascade_count = uint32_t(r.cascades.size());
    d.iterations = c.iterations;
    d.sh_coefficients = 4;
    d.units = GIBAKE_UNITS_CANDELA;
    d.flags = c.occlusion ? GIBAKE_LPV_FLAG_OCCLUSION : 0u;
    const uint32_t group = uint32_t(out.size());
    PendingSection desc{GIBAKE_SECTION_LPV_CASCADE, GIBAKE_FORMAT_STRUCT, group, 1, {}};
    append(desc.bytes, d);
    out.push_back(std::move(desc));
    out.push_back(precision_section(GIBAKE_SECTION_LPV_SH, GIBAKE_FORMAT_F16, GIBAKE_FORMAT_F32, group, 1, c.sh, o.sh,
                                    arena));
  }
}

// The file's minor version: 5 with a sparse volume or an RGB9E5 atlas, 4 with a volume index, 3 with voxel GI, else 2
// (each addition says its minor only where it is present, so files without it keep the bytes of
// earlier writers).
int file_minor(const BakeOutputs& outputs, bool indexed, bool sparse) {
  if (sparse) return GIBAKE_VERSION_MINOR_SPARSE;
  if (indexed) return GIBAKE_VERSION_MINOR_INDEX;
  return outputs.vxgi ? GIBAKE_VERSION_MINOR_VXGI : GIBAKE_VERSION_MINOR;
}

// The ddgi_volume_index (1.4) of every DDGI volume among `sections` (those of the outputs and any
// given as raw sections), in file order; none for fewer than two volumes.
bool add_volume_index(std::vector<PendingSection>& sections) {
  std::vector<gibake_ddgi_volume> volumes;
  for (const PendingSection& s : sections) {
    if (s.type != GIBAKE_SECTION_DDGI_VOLUME || s.bytes.size() != sizeof(gibake_ddgi_volume)) continue;
    volumes.emplace_back();
    std::memcpy(&volumes.back(), s.bytes.data(), sizeof(gibake_ddgi_volume));
  }
  const std::vector<uint32_t> words = loader::build_ddgi_volume_index(volumes);
  if (words.empty()) return false;
  PendingSection index{GIBAKE_SECTION_DDGI_VOLUME_INDEX, GIBAKE_FORMAT_U32, 0, words.size(), {}};
  index.bytes.resize(words.size() * 4);
  std::memcpy(index.bytes.data(), words.data(), index.bytes.size());
  sections.push_back(std::move(index));
  return true;
}

Status make_metadata(const BakeOutputs& outputs, int minor, std::string& out) {
  nlohmann::json meta = nlohmann::json::object();
  try {
    if (!outputs.metadata_json.empty()) meta = nlohmann::json::parse(outputs.metadata_json);
    if (!meta.is_object()) return Status::invalid("", "metadata", "metadata JSON is not an object");
    if (outputs.ddgi && !outputs.ddgi->settings_json.empty() && !meta.contains("settings"))
      meta["settings"] = nlohmann::json::parse(outputs.ddgi->settings_json);
    if (outputs.lpv && !outputs.lpv->settings_json.empty()) {
      if (!meta.contains("settings")) meta["settings"] = nlohmann::json::object();
      if (meta["settings"].is_object() && !meta["settings"].contains("lpv"))
        meta["settings"]["lpv"] = nlohmann::json::parse(outputs.lpv->settings_json);
    }
  } catch (const nlohmann::json::exception& e) {
    return Status::invalid("", "metadata", std::string("invalid JSON: ") + e.what());
  }
  if (!meta.contains("gibake_version")) meta["gibake_version"] = GIBAKE_VERSION;
  meta["format_version"] = std::to_string(GIBAKE_VERSION_MAJOR) + "." + std::to_string(minor);
  out = meta.dump();
  return Status::ok();
}

uint64_t align16(uint64_t v) { return (v + 15) & ~uint64_t(15); }

// Where each section goes: offsets 16-aligned after the header and a table of `entries` sections
// (the file's; more than `sections` when only its first sections are laid out), in order.
uint64_t lay_out(const std::vector<PendingSection>& sections, std::vector<gibake_section_entry>& table,
                 size_t entries) {
  table.assign(sections.size(), gibake_section_entry{});
  uint64_t at = align16(sizeof(gibake_file_header) + entries * sizeof(gibake_section_entry));
  for (size_t i = 0; i < sections.size(); ++i) {
    const PendingSection& s = sections[i];
    gibake_section_entry& e = table[i];
    e.type = s.type;
    e.format = s.format;
    e.offset = at;
    e.size = s.size();
    e.count = s.count;
    e.group = s.group;
    at = align16(at + e.size);
  }
  return at;
}

// A section known by its size alone.
PendingSection sized_section(uint32_t type, uint32_t format, uint64_t count, uint64_t size) {
  PendingSection s{type, format, 0, count, {}};
  s.given_size = size;
  return s;
}

using RangeSink = std::function<void(uint64_t offset, const uint8_t* data, size_t size)>;

// Hands [offset, offset + size) of `file` to `sink`: a large range in pieces side by side, so that
// copying it into the page cache runs on every thread rather than on the one that built it.
constexpr size_t kSinkPiece = size_t(4) << 20;

void sink_range(const RangeSink& sink, uint64_t offset, const uint8_t* data, size_t size) {
  const size_t pieces = (size + kSinkPiece - 1) / kSinkPiece;
  if (pieces < 2) {
    sink(offset, data, size);
    return;
  }
  tbb::parallel_for(size_t(0), pieces, [&](size_t k) {
    const size_t at = k * kSinkPiece;
    sink(offset + at, data + at, std::min(kSinkPiece, size - at));
  });
}

// Fills `file` (the size lay_out returned, uninitialised): every section encoded or copied into
// place and checksummed by one task, sections side by side and a large section's chunks too, then
// the zero padding, the table and the header. Each byte depends only on the inputs, so the file is
// the same for any thread count. Returns how many values were clamped to the float16 range.
// Each finished range (a section with its padding, in pieces of up to 4 MiB, then the header and
// table) is handed to `sink` when given, beside the section's checksum.
size_t fill_file(const std::vector<PendingSection>& sections, std::vector<gibake_section_entry>& table,
                 uint64_t file_size, uint64_t input_hash, uint16_t minor, uint8_t* file, tbb::task_arena& arena,
                 const RangeSink& sink) {
  std::atomic<size_t> clamped{0};
  arena.execute([&] {
    tbb::parallel_for(size_t(0), sections.size(), [&](size_t i) {
      if (sections[i].streamed) {  // bytes, padding and checksum done: the buffer holds them
        table[i].checksum = sections[i].checksum;
        return;
      }
      uint8_t* dst = file + table[i].offset;
      fill_payload(sections[i], dst, clamped);
      const uint64_t end = i + 1 < sections.size() ? table[i + 1].offset : file_size;
      std::memset(dst + table[i].size, 0, size_t(end - table[i].offset - table[i].size));
      // The checksum (one pass on one thread) and the write only read the finished bytes.
      tbb::parallel_invoke([&] { table[i].checksum = loader::xxh64(dst, size_t(table[i].size), GIBAKE_HASH_SEED); },
                           [&] {
                             if (sink) sink_range(sink, table[i].offset, dst, size_t(end - table[i].offset));
                           });
    });
  });
  gibake_file_header h{};
  std::memcpy(h.magic, GIBAKE_MAGIC_BYTES, GIBAKE_MAGIC_SIZE);
  h.version_major = GIBAKE_VERSION_MAJOR;
  h.version_minor = minor;
  h.header_size = sizeof(gibake_file_header);
  h.section_count = uint32_t(sections.size());
  h.section_table_offset = sizeof(gibake_file_header);
  h.input_hash = input_hash;
  h.file_size = file_size;
  const size_t table_bytes = table.size() * sizeof(gibake_section_entry);
  const uint64_t first = table.empty() ? file_size : table[0].offset;
  std::memset(file + sizeof h, 0, size_t(first - sizeof h));
  if (!table.empty()) std::memcpy(file + h.section_table_offset, table.data(), table_bytes);
  h.table_checksum = loader::xxh64(file + h.section_table_offset, table_bytes, GIBAKE_HASH_SEED);
  h.header_checksum = 0;
  h.header_checksum = loader::xxh64(&h, sizeof h, GIBAKE_HASH_SEED);
  std::memcpy(file, &h, sizeof h);
  if (sink) sink(0, file, size_t(first));
  return clamped;
}

std::string canonical_settings(const std::string& settings) {
  try {
    return nlohmann::json::parse(settings).dump();
  } catch (const nlohmann::json::exception&) {
    return settings;
  }
}

void hash_string(XXH3_state_t* state, const std::string& s) {
  const uint64_t size = s.size();
  XXH3_64bits_update(state, &size, sizeof size);
  XXH3_64bits_update(state, s.data(), s.size());
}

}  // namespace

const char* gibake_version_string() { return GIBAKE_VERSION; }

gibake_ddgi_volume ddgi_volume_record(const DdgiVolumeDesc& desc) {
  gibake_ddgi_volume d{};
  for (int i = 0; i < 3; ++i) {
    d.grid_min[i] = desc.grid_min[i];
    d.grid_max[i] = desc.grid_max[i];
    d.spacing[i] = desc.spacing[i];
    d.counts[i] = desc.counts[i];
  }
  d.max_distance = desc.max_distance;
  d.probe_count = uint32_t(desc.probe_count());
  d.sh_order = uint32_t(desc.sh_order);
  d.sh_coefficients = uint32_t(desc.sh_coefficients());
  d.radiance_units = GIBAKE_UNITS_CANDELA_PER_M2;
  d.irradiance_units = GIBAKE_UNITS_LUX;
  d.irradiance_tile = kIrradianceTexels;
  d.depth_tile = kDepthTexels;
  d.tile_border = 1;
  return d;
}

InputHash::InputHash() : state_(XXH3_createState(), [](XXH3_state_t* s) { XXH3_freeState(s); }) {
  if (state_) XXH3_64bits_reset(state_.get());
}

Status InputHash::add_files(const std::vector<std::string>& files) {
  if (!state_) return Status::error(ExitCode::RuntimeFailure, "", "hash", "out of memory");
  std::vector<char> buffer(1 << 20);
  for (const std::string& file : files) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return Status::io(file, "cannot open input for hashing");
    uint64_t total = 0;
    while (in) {
      in.read(buffer.data(), std::streamsize(buffer.size()));
      const std::streamsize n = in.gcount();
      if (n > 0) XXH3_64bits_update(state_.get(), buffer.data(), size_t(n));
      total += uint64_t(std::max<std::streamsize>(n, 0));
    }
    if (in.bad()) return Status::io(file, "read failed while hashing");
    XXH3_64bits_update(state_.get(), &total, sizeof total);  // separates files
  }
  return Status::ok();
}

Status InputHash::finish(const std::string& settings, uint64_t& out) const {
  std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(), &XXH3_freeState);
  if (!state_ || !state) return Status::error(ExitCode::RuntimeFailure, "", "hash", "out of memory");
  XXH3_copyState(state.get(), state_.get());
  hash_string(state.get(), canonical_settings(settings));
  hash_string(state.get(), GIBAKE_VERSION);
  out = XXH3_64bits_digest(state.get());
  return Status::ok();
}

Status hash_inputs(const std::vector<std::string>& files, const std::string& settings, uint64_t& out) {
  InputHash hash;
  GIBAKE_TRY(hash.add_files(files));
  return hash.finish(settings, out);
}

namespace {

// The sparse form of a volume that asks for it (DdgiResult::sparse), kept in `held` while its
// sections are encoded; null for a volume written in its grid's layout.
const SparseVolume* sparse_form(const DdgiResult& r, const BakeFileOptions& options,
                                std::vector<std::unique_ptr<SparseVolume>>& held) {
  if (!r.sparse || options.dense_volumes) return nullptr;
  auto sparse = std::make_unique<SparseVolume>();
  if (!make_sparse_volume(r, *sparse)) return nullptr;
  held.push_back(std::move(sparse));
  return held.back().get();
}

// Checks the outputs and turns them into sections (float payloads still to encode; sparse volumes'
// payloads in `held`). `first_atlas` (optional): the first volume's atlas precision, decided by a
// stream that saw every value.
Status collect_sections(const BakeOutputs& outputs, const BakeFileOptions& options, tbb::task_arena& arena,
                        std::vector<PendingSection>& sections, std::vector<std::unique_ptr<SparseVolume>>& held,
                        size_t& clamped, int& minor, const FloatPrecision* first_atlas = nullptr) {
  if (outputs.ddgi) {
    GIBAKE_TRY(check_ddgi(*outputs.ddgi));
    BakeFileOptions first = options;
    if (first_atlas) first.atlas = *first_atlas;
    add_ddgi_sections(*outputs.ddgi, first, 0, sections, &arena, sparse_form(*outputs.ddgi, options, held));
  }
  for (const DdgiResult* more : outputs.ddgi_more) {
    GIBAKE_TRY(check_ddgi(*more));
    add_ddgi_sections(*more, options, uint32_t(sections.size()), sections, &arena, sparse_form(*more, options, held));
  }
  if (outputs.lpv) {
    GIBAKE_TRY(check_lpv(*outputs.lpv));
    add_lpv_sections(*outputs.lpv, options, sections, &arena);
  }
  if (outputs.vxgi) {
    std::vector<EncodedSection> vx;
    GIBAKE_TRY(encode_vxgi_sections(*outputs.vxgi, uint32_t(sections.size()), options.vxgi == FloatPrecision::Auto,
                                    options.vxgi == FloatPrecision::Half, vx, clamped));
    for (EncodedSection& e : vx) sections.push_back({e.type, e.format, e.group, e.count, std::move(e.bytes)});
  }
  if (outputs.extra) {
    const uint32_t base = uint32_t(sections.size());
    for (const RawSection& r : *outputs.extra) sections.push_back({r.type, r.format, base + r.group, r.count, r.bytes});
  }
  const bool sparse = std::any_of(sections.begin(), sections.end(), [](const PendingSection& s) {
    // the outputs' or a raw section's
    return s.type == GIBAKE_SECTION_DDGI_PROBE_SLOTS || s.format == GIBAKE_FORMAT_RGB9E5;
  });
  minor = file_minor(outputs, add_volume_index(sections), sparse);
  std::string metadata;
  GIBAKE_TRY(make_metadata(outputs, minor, metadata));
  sections.push_back({GIBAKE_SECTION_METADATA, GIBAKE_FORMAT_JSON, 0, metadata.size(),
                      std::vector<uint8_t>(metadata.begin(), metadata.end())});
  return Status::ok();
}

// A stream's atlases (options.stream): finished, and adopted when the outputs lay out as the
// stream predicted (their sections then marked streamed); else the stream is abandoned.
struct StreamUse {
  BakeFileStream* stream = nullptr;
  bool finished = false, adopted = false;
  size_t clamped = 0;
  FloatPrecision precision = FloatPrecision::Auto;
};

void finish_stream(const BakeOutputs& outputs, const BakeFileOptions& options, tbb::task_arena& arena, StreamUse& use) {
  use.stream = options.stream;
  if (!use.stream) return;
  const auto t0 = Clock::now();
  use.finished =
      outputs.ddgi && use.stream->finish(outputs.ddgi->irradiance_atlas, outputs.ddgi->depth_atlas, arena, use.clamped);
  use.precision = use.stream->atlas_half() ? FloatPrecision::Half : FloatPrecision::Full;
  if (use.finished && options.timing) options.timing("streamed atlas rows left", seconds_since(t0));
}

void adopt_stream(const std::vector<gibake_section_entry>& table, std::vector<PendingSection>& sections,
                  StreamUse& use) {
  if (!use.stream) return;
  use.adopted = use.finished && use.stream->matches(table);
  if (!use.adopted) {
    use.stream->abandon();
    return;
  }
  for (PendingSection& s : sections) {
    if (s.group != 0) continue;
    if (s.type == GIBAKE_SECTION_DDGI_IRRADIANCE) s.checksum = use.stream->checksum(BakeFileStream::kIrradiance);
    if (s.type == GIBAKE_SECTION_DDGI_DEPTH) s.checksum = use.stream->checksum(BakeFileStream::kDepth);
    s.streamed = s.type == GIBAKE_SECTION_DDGI_IRRADIANCE || s.type == GIBAKE_SECTION_DDGI_DEPTH;
  }
}

// The file's bytes in the buffer `allocate(size, streamed)` hands out for its size: sections,
// layout, encoding, checksums, and the loader's self-check. `begin(streamed)` (optional) runs once
// the outputs are checked and before any encoding; `sink` (optional) receives each finished range
// of the file. `streamed`: options.stream's file and buffer are adopted.
template <class Allocate>
Status build_into(const BakeOutputs& outputs, const BakeFileOptions& options, Allocate&& allocate,
                  const std::function<Status(bool streamed)>& begin = {}, const RangeSink& sink = {}) {
  std::vector<PendingSection> sections;
  std::vector<std::unique_ptr<SparseVolume>> sparse;  // what sparse volumes' sections point into
  size_t clamped = 0;
  tbb::task_arena arena(options.threads > 0 ? int(options.threads) : tbb::task_arena::automatic);
  StreamUse stream;
  finish_stream(outputs, options, arena, stream);
  int minor = GIBAKE_VERSION_MINOR;
  const Status collected = collect_sections(outputs, options, arena, sections, sparse, clamped, minor,
                                            stream.finished ? &stream.precision : nullptr);
  if (!collected && stream.stream) stream.stream->abandon();
  GIBAKE_TRY(collected);
  std::vector<gibake_section_entry> table;
  const uint64_t size = lay_out(sections, table, sections.size());
  adopt_stream(table, sections, stream);
  if (stream.adopted) clamped += stream.clamped;
  if (begin) GIBAKE_TRY(begin(stream.adopted));
  uint8_t* file = allocate(size_t(size), stream.adopted);
  if (!file) return Status::io("", "out of memory for the bake file's " + std::to_string(size) + " bytes");
  clamped += fill_file(sections, table, size, outputs.input_hash, uint16_t(minor), file, arena, sink);
  if (clamped && options.warn)
    options.warn(std::to_string(clamped) + " values above the float16 range were clamped to 65504");
  // Self-check: whatever we write, the loader must accept (catches inconsistent atlas layouts).
  loader::BakeFile check;
  if (loader::Error e = check.open_borrowed(file, size_t(size), loader::LoadOptions{false}))
    return Status::invalid("", "bake result", "would write an invalid file: " + e.message);
  // Light beyond a float (a light, an emission or a sky map too strong) is refused, not written:
  // every reader would turn it into NaN.
  std::string first;
  if (const uint64_t bad = count_non_finite_light(check, first))
    return Status::error(ExitCode::RuntimeFailure, "", "bake result",
                         std::to_string(bad) + " value(s) NaN, infinite or beyond 1e36, first in " + first +
                             ": the light overflowed 32-bit floats (a light, an emission or a sky map too strong)");
  return Status::ok();
}

}  // namespace

bool predict_ddgi_table(const DdgiFileShape& shape, const BakeFileOptions& options, bool atlas_half,
                        std::vector<gibake_section_entry>& table, uint64_t& end) {
  if (options.sh == FloatPrecision::Auto) return false;
  const bool sh_half = options.sh == FloatPrecision::Half;
  const uint64_t n = shape.probes, atlas_bytes = atlas_half ? 2 : 4;
  const uint64_t irr = uint64_t(shape.irradiance_width) * uint64_t(shape.irradiance_height);
  const uint64_t depth = uint64_t(shape.depth_width) * uint64_t(shape.depth_height);
  // add_ddgi_sections' order and sizes, for a whole bake's volume (every per-probe section present).
  const std::vector<PendingSection> sections{
      sized_section(GIBAKE_SECTION_DDGI_VOLUME, GIBAKE_FORMAT_STRUCT, 1, sizeof(gibake_ddgi_volume)),
      sized_section(GIBAKE_SECTION_DDGI_SH, sh_half ? GIBAKE_FORMAT_F16 : GIBAKE_FORMAT_F32, shape.sh_values,
                    shape.sh_values * (sh_half ? 2 : 4)),
      sized_section(GIBAKE_SECTION_DDGI_OFFSETS, GIBAKE_FORMAT_F32X3, n, n * 12),
      sized_section(GIBAKE_SECTION_DDGI_STATES, GIBAKE_FORMAT_U8, n, n),
      sized_section(GIBAKE_SECTION_DDGI_STATS, GIBAKE_FORMAT_PROBE_STATS, n, n * sizeof(gibake_probe_stats)),
      sized_section(GIBAKE_SECTION_DDGI_IRRADIANCE, atlas_half ? GIBAKE_FORMAT_RGBA16F : GIBAKE_FORMAT_RGBA32F, irr,
                    irr * 4 * atlas_bytes),
      sized_section(GIBAKE_SECTION_DDGI_DEPTH, atlas_half ? GIBAKE_FORMAT_RG16F : GIBAKE_FORMAT_RG32F, depth,
                    depth * 2 * atlas_bytes)};
  if (n == 0 || irr == 0 || depth == 0) return false;
  end = lay_out(sections, table, sections.size() + 1);  // the metadata after them
  return true;
}

Status build_bake_file(const BakeOutputs& outputs, const BakeFileOptions& options, std::vector<uint8_t>& out) {
  BakeFileOptions no_stream = options;
  no_stream.stream = nullptr;
  return build_into(outputs, no_stream, [&](size_t size, bool) {
    out.resize(size);
    return out.data();
  });
}

// Each section goes to the temporary file as soon as it is encoded and checksummed (pwrite from its
// task, writeback started at once), so the copy into the page cache runs on every thread and the
// disk writes while later sections are still being built; one fsync at the commit.
Status write_bake_file(const std::string& path, const BakeOutputs& outputs, const BakeFileOptions& options,
                       const std::vector<std::string>& inputs, const BytesReader& while_committing) {
  AtomicFile own_file;
  AtomicFile* file = &own_file;                                         // or the stream's
  std::unique_ptr<uint8_t, void (*)(void*)> bytes(nullptr, std::free);  // left uninitialised: every byte is written
  size_t size = 0;
  std::mutex failed_mutex;
  Status failed = Status::ok();
  const auto allocate = [&](size_t n, bool streamed) {
    bytes.reset(streamed ? options.stream->take_buffer(n) : static_cast<uint8_t*>(std::malloc(n)));
    size = n;
    return bytes.get();
  };
  const std::function<Status(bool)> begin = [&](bool streamed) {
    if (!streamed) return own_file.begin(path, inputs);
    file = &options.stream->file();
    return Status::ok();
  };
  const RangeSink sink = [&](uint64_t offset, const uint8_t* data, size_t n) {
    Status st = file->write_at(offset, data, n);
    std::lock_guard<std::mutex> lock(failed_mutex);
    if (!st && failed) failed = st;
  };
  const auto t_build = Clock::now();
  Status s = build_into(outputs, options, allocate, begin, sink);
  if (!s) return Status::error(s.code(), s.file().empty() ? path : s.file(), s.where(), s.what());
  GIBAKE_TRY(failed);  // the temporary is removed with `file`
  if (options.timing) options.timing("encoded and written", seconds_since(t_build));
  double commit_seconds = 0.0;
  const auto commit = [&] {
    const auto t_commit = Clock::now();
    const Status c = file->commit();
    commit_seconds = seconds_since(t_commit);
    return c;
  };
  if (!while_committing) {
    GIBAKE_TRY(commit());
  } else {
    std::future<Status> committed = std::async(std::launch::async, commit);
    const Status read = while_committing(bytes.get(), size);
    GIBAKE_TRY(committed.get());
    GIBAKE_TRY(read);
  }
  if (options.timing) options.timing("committed", commit_seconds);
  return Status::ok();
}

Status write_bake_file(const std::string& path, const BakeOutputs& outputs, const BakeFileOptions& options,
                       const std::vector<std::string>& inputs) {
  return write_bake_file(path, outputs, options, inputs, BytesReader{});
}

}  // namespace gibake
