// Opening and validating bake files: every offset and size is checked before it is used.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "gibake/loader.hpp"

namespace gibake::loader {
namespace {

Error fail(ErrorCode code, std::string message) { return Error{code, std::move(message)}; }

std::string section_label(uint32_t index, uint32_t type) {
  return "section " + std::to_string(index) + " (" + section_type_name(type) + ")";
}

std::string hex_byte(uint8_t v) {
  const char* digits = "0123456789abcdef";
  return std::string{digits[v >> 4], digits[v & 15]};
}

uint64_t align16(uint64_t v) {
  return (v + GIBAKE_SECTION_ALIGNMENT - 1) / GIBAKE_SECTION_ALIGNMENT * GIBAKE_SECTION_ALIGNMENT;
}

bool in_file(uint64_t offset, uint64_t size, uint64_t file_size) {
  return offset <= file_size && size <= file_size - offset;
}

struct Range {
  uint64_t begin, end;
  std::string label;
};

// What occupies the file, in offset order: the header, the section table (when it has entries)
// and every non-empty section payload.
std::vector<Range> occupied_ranges(const gibake_file_header& header, const std::vector<gibake_section_entry>& sections) {
  std::vector<Range> ranges;
  ranges.push_back({0, header.header_size, "the header"});
  const uint64_t table_bytes = uint64_t(header.section_count) * sizeof(gibake_section_entry);
  if (table_bytes > 0)
    ranges.push_back({header.section_table_offset, header.section_table_offset + table_bytes, "the section table"});
  for (uint32_t i = 0; i < sections.size(); ++i)
    if (sections[i].size > 0)
      ranges.push_back({sections[i].offset, sections[i].offset + sections[i].size, section_label(i, sections[i].type)});
  std::sort(ranges.begin(), ranges.end(), [](const Range& a, const Range& b) { return a.begin < b.begin; });
  return ranges;
}

// Expected element format(s) for known types; size of a STRUCT element.
bool format_allowed(uint32_t type, uint32_t format) {
  switch (type) {
    case GIBAKE_SECTION_DDGI_VOLUME: return format == GIBAKE_FORMAT_STRUCT;
    case GIBAKE_SECTION_DDGI_SH: return format == GIBAKE_FORMAT_F32 || format == GIBAKE_FORMAT_F16;
    case GIBAKE_SECTION_DDGI_OFFSETS: return format == GIBAKE_FORMAT_F32X3;
    case GIBAKE_SECTION_DDGI_STATES: return format == GIBAKE_FORMAT_U8 || format == GIBAKE_FORMAT_U32;
    case GIBAKE_SECTION_DDGI_STATS: return format == GIBAKE_FORMAT_PROBE_STATS;
    case GIBAKE_SECTION_DDGI_IRRADIANCE:
      return format == GIBAKE_FORMAT_RGBA16F || format == GIBAKE_FORMAT_RGBA32F || format == GIBAKE_FORMAT_RGB9E5;
    case GIBAKE_SECTION_DDGI_DEPTH: return format == GIBAKE_FORMAT_RG16F || format == GIBAKE_FORMAT_RG32F;
    case GIBAKE_SECTION_METADATA: return format == GIBAKE_FORMAT_JSON;
    case GIBAKE_SECTION_LPV_CASCADE: return format == GIBAKE_FORMAT_STRUCT;
    case GIBAKE_SECTION_LPV_SH: return format == GIBAKE_FORMAT_F32 || format == GIBAKE_FORMAT_F16;
    case GIBAKE_SECTION_VXGI_VOLUME: return format == GIBAKE_FORMAT_STRUCT;
    case GIBAKE_SECTION_VXGI_RADIANCE: return format == GIBAKE_FORMAT_RGBA16F || format == GIBAKE_FORMAT_RGBA32F;
    case GIBAKE_SECTION_VXGI_SDF: return format == GIBAKE_FORMAT_F32 || format == GIBAKE_FORMAT_F16;
    case GIBAKE_SECTION_DDGI_VOLUME_INDEX: return format == GIBAKE_FORMAT_U32;
    case GIBAKE_SECTION_DDGI_PROBE_SLOTS:
      return format == GIBAKE_FORMAT_U32;
    default: return true;  // unknown types are skipped
  }
}

bool known_type(uint32_t type) {
  return (type >= GIBAKE_SECTION_DDGI_VOLUME && type <= GIBAKE_SECTION_METADATA) ||
         (type >= GIBAKE_SECTION_LPV_CASCADE && type <= GIBAKE_SECTION_DDGI_PROBE_SLOTS);
}

uint64_t element_size(uint32_t type, uint32_t format) {
  if (format == GIBAKE_FORMAT_STRUCT) {
    if (type == GIBAKE_SECTION_DDGI_VOLUME) return sizeof(gibake_ddgi_volume);
    if (type == GIBAKE_SECTION_VXGI_VOLUME) return sizeof(gibake_vxgi_volume);
    return type == GIBAKE_SECTION_LPV_CASCADE ? sizeof(gibake_lpv_cascade) : 0;
  }
  return gibake_format_element_size(format);
}

}  // namespace

const char* error_code_name(ErrorCode code) {
  static const char* const kNames[] = {
      "ok", "io_error", "truncated", "bad_magic", "unsupported_version", "bad_header",
      "header_checksum", "bad_section_table", "table_checksum", "section_out_of_range",
      "section_misaligned", "section_overlap", "bad_element_format", "section_checksum",
      "bad_volume", "missing_section", "duplicate_section", "bad_padding"};
  const int i = static_cast<int>(code);
  return i >= 0 && i < int(sizeof(kNames) / sizeof(kNames[0])) ? kNames[i] : "unknown";
}

const char* section_type_name(uint32_t type) {
  switch (type) {
    case GIBAKE_SECTION_DDGI_VOLUME: return "ddgi_volume";
    case GIBAKE_SECTION_DDGI_SH: return "ddgi_sh";
    case GIBAKE_SECTION_DDGI_OFFSETS: return "ddgi_offsets";
    case GIBAKE_SECTION_DDGI_STATES: return "ddgi_states";
    case GIBAKE_SECTION_DDGI_STATS: return "ddgi_stats";
    case GIBAKE_SECTION_DDGI_IRRADIANCE: return "ddgi_irradiance";
    case GIBAKE_SECTION_DDGI_DEPTH: return "ddgi_depth";
    case GIBAKE_SECTION_METADATA: return "metadata";
    case GIBAKE_SECTION_LPV_CASCADE: return "lpv_cascade";
    case GIBAKE_SECTION_VXGI_VOLUME: return "vxgi_volume";
    case GIBAKE_SECTION_LPV_SH: return "lpv_sh";
    case GIBAKE_SECTION_SHARD_INFO: return "shard_info";
    case GIBAKE_SECTION_SHARD_PROBES: return "shard_probes";
    case GIBAKE_SECTION_SHARD_SH0: return "shard_sh0";
    case GIBAKE_SECTION_SHARD_IRRADIANCE: return "shard_irradiance";
    case GIBAKE_SECTION_SHARD_DEPTH: return "shard_depth";
    case GIBAKE_SECTION_SHARD_BOUNCE_HITS: return "shard_hits";
    case GIBAKE_SECTION_VXGI_RADIANCE: return "vxgi_radiance";
    case GIBAKE_SECTION_VXGI_SDF: return "vxgi_sdf";
    case GIBAKE_SECTION_DDGI_VOLUME_INDEX: return "ddgi_volume_index";
    case GIBAKE_SECTION_DDGI_PROBE_SLOTS:
      return "ddgi_probe_slots";
    default: return "unknown";
  }
}

const char* element_format_name(uint32_t format) {
  static const char* const kNames[] = {"unknown", "struct",  "f32",   "f16",   "f32x3",       "u8",   "u32",
                                       "rgba16f", "rgba32f", "rg16f", "rg32f", "probe_stats", "json", "rgb9e5"};
  return format < sizeof(kNames) / sizeof(kNames[0]) ? kNames[format] : "unknown";
}

void BakeFile::reset() {
  data_ = nullptr;
  size_ = 0;
  header_ = gibake_file_header{};
  sections_.clear();
  volumes_.clear();
  ddgi_order_.clear();
  index_ = DdgiVolumeIndex{};
  lpv_.clear();
  vxgi_.clear();
  tiles_.clear();
  metadata_section_ = -1;
}

Error BakeFile::open(const std::string& path, const LoadOptions& options) {
  reset();
  owned_.clear();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail(ErrorCode::IoError, "not a regular file or cannot be opened");
  const uintmax_t file_size = std::filesystem::file_size(path, ec);
  if (ec) return fail(ErrorCode::IoError, "cannot determine file size: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::IoError, "cannot open file");
  std::vector<uint8_t> bytes;
  try {
    bytes.resize(static_cast<size_t>(file_size));
  } catch (const std::exception&) {
    return fail(ErrorCode::IoError, "file too large to read (" + std::to_string(file_size) + " bytes)");
  }
  if (!bytes.empty() && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())))
    return fail(ErrorCode::IoError, "read failed");
  return open(std::move(bytes), options);
}

Error BakeFile::open(std::vector<uint8_t>&& bytes, const LoadOptions& options) {
  reset();
  owned_ = std::move(bytes);
  data_ = owned_.data();
  size_ = owned_.size();
  Error e = validate(options);
  if (e) reset();
  return e;
}

Error BakeFile::open_borrowed(const void* data, size_t size, const LoadOptions& options) {
  reset();
  owned_.clear();
  if (data == nullptr && size != 0) return fail(ErrorCode::IoError, "null buffer");
  data_ = static_cast<const uint8_t*>(data);
  size_ = size;
  Error e = validate(options);
  if (e) reset();
  return e;
}

const uint8_t* BakeFile::section_data(uint32_t index) const {
  return index < sections_.size() ? data_ + sections_[index].offset : nullptr;
}

std::string BakeFile::metadata_json() const {
  if (metadata_section_ < 0) return {};
  const gibake_section_entry& s = sections_[static_cast<size_t>(metadata_section_)];
  return std::string(reinterpret_cast<const char*>(data_ + s.offset), static_cast<size_t>(s.size));
}

Error BakeFile::validate(const LoadOptions& options) {
  if (size_ < sizeof(gibake_file_header))
    return fail(ErrorCode::Truncated, "file is " + std::to_string(size_) + " bytes, shorter than the header");
  std::memcpy(&header_, data_, sizeof header_);
  if (std::memcmp(header_.magic, GIBAKE_MAGIC_BYTES, GIBAKE_MAGIC_SIZE) != 0)
    return fail(ErrorCode::BadMagic, "not a gibake file (bad magic)");
  if (header_.version_major != GIBAKE_VERSION_MAJOR)
    return fail(ErrorCode::UnsupportedVersion,
                "unsupported major version " + std::to_string(header_.version_major) +
                    " (this loader reads " + std::to_string(GIBAKE_VERSION_MAJOR) + ".x)");
  if (header_.header_size < sizeof(gibake_file_header) || header_.header_size > size_ ||
      header_.header_size % GIBAKE_SECTION_ALIGNMENT != 0)
    return fail(ErrorCode::BadHeader, "header_size " + std::to_string(header_.header_size) + " out of range");
  // Reserved in every 1.x: a set bit is a feature this loader cannot know to honour.
  if (header_.flags != 0)
    return fail(ErrorCode::BadHeader, "header flags " + std::to_string(header_.flags) + " set; 1.x defines none");
  if (header_.file_size > size_)
    return fail(ErrorCode::Truncated, "file is " + std::to_string(size_) + " bytes, header says " +
                                          std::to_string(header_.file_size));
  if (header_.file_size < size_)
    return fail(ErrorCode::BadHeader, "file is " + std::to_string(size_) +
                                          " bytes, longer than the recorded " + std::to_string(header_.file_size));
  if (options.verify_checksums) {
    std::vector<uint8_t> copy(data_, data_ + header_.header_size);
    std::memset(copy.data() + offsetof(gibake_file_header, header_checksum), 0, 8);
    if (xxh64(copy.data(), copy.size(), GIBAKE_HASH_SEED) != header_.header_checksum)
      return fail(ErrorCode::HeaderChecksum, "header checksum mismatch");
  }
  const uint64_t table_bytes = uint64_t(header_.section_count) * sizeof(gibake_section_entry);
  if (header_.section_table_offset % GIBAKE_SECTION_ALIGNMENT != 0 ||
      header_.section_table_offset < header_.header_size ||
      !in_file(header_.section_table_offset, table_bytes, size_))
    return fail(ErrorCode::BadSectionTable, "section table (" + std::to_string(header_.section_count) +
                                                " entries at " + std::to_string(header_.section_table_offset) +
                                                ") is outside the file or misaligned");
  const uint8_t* table = data_ + header_.section_table_offset;
  if (options.verify_checksums && xxh64(table, table_bytes, GIBAKE_HASH_SEED) != header_.table_checksum)
    return fail(ErrorCode::TableChecksum, "section table checksum mismatch");
  sections_.resize(header_.section_count);
  if (table_bytes) std::memcpy(sections_.data(), table, table_bytes);
  if (Error e = validate_sections(options)) return e;
  if (Error e = build_volumes()) return e;
  order_ddgi_volumes();
  if (Error e = build_ddgi_index()) return e;
  if (Error e = build_lpv()) return e;
  if (Error e = build_vxgi()) return e;
  if (Error e = validate_layout(options)) return e;
  if (options.probe_major_tiles) build_probe_tiles();
  return {};
}

// Every byte of the file is accounted for: the header, the section table and the non-empty
// section payloads, in offset order (any order of table entries), each starting at the previous
// one's end rounded up to 16, padding bytes zero, and the file ending at the last one's end
// rounded up to 16. That is exactly the writer's layout (io/bake_file.cpp) with the freedom the
// format gives (header_size > 64, the table after a larger header, sections in any order), and
// it leaves nowhere to hide bytes that no checksum covers. Runs last, so the structural errors
// above keep their codes. The zero-padding test reads at most 15 bytes per section; like the
// checksums it is an integrity check of the bytes and is skipped with verify_checksums = false
// (trusted files); the gap and end-of-file rules are structural and always apply.
Error BakeFile::validate_layout(const LoadOptions& options) const {
  const std::vector<Range> ranges = occupied_ranges(header_, sections_);
  const auto check_zero = [&](uint64_t begin, uint64_t end, const std::string& what) -> Error {
    if (!options.verify_checksums) return {};
    for (uint64_t at = begin; at < end; ++at)
      if (data_[at] != 0)
        return fail(ErrorCode::BadPadding, "non-zero padding byte 0x" + hex_byte(data_[at]) + " at offset " +
                                               std::to_string(at) + " (" + what + ")");
    return {};
  };
  for (size_t i = 1; i < ranges.size(); ++i) {
    const Range& prev = ranges[i - 1];
    const Range& next = ranges[i];
    const uint64_t expected = align16(prev.end);
    if (next.begin != expected)
      return fail(ErrorCode::BadPadding, "bytes [" + std::to_string(prev.end) + ", " + std::to_string(next.begin) +
                                             ") between " + prev.label + " and " + next.label +
                                             " are not explained by the layout (" + next.label +
                                             " should start at offset " + std::to_string(expected) + ")");
    if (Error e = check_zero(prev.end, next.begin, "padding after " + prev.label)) return e;
  }
  const Range& last = ranges.back();
  const uint64_t end = align16(last.end);
  if (size_ > end)
    return fail(ErrorCode::BadPadding, std::to_string(size_ - end) + " bytes at offset " + std::to_string(end) +
                                           " follow the padded end of " + last.label + " (the file must end there)");
  if (size_ < end)  // only a file whose last payload is not padded to 16 bytes
    return fail(ErrorCode::BadPadding, "the file ends at " + std::to_string(size_) + ", inside the padding of " +
                                           last.label + " (expected end " + std::to_string(end) + ")");
  return check_zero(last.end, end, "padding after " + last.label);
}

Error BakeFile::validate_sections(const LoadOptions& options) {
  for (uint32_t i = 0; i < sections_.size(); ++i) {
    const gibake_section_entry& s = sections_[i];
    const std::string label = section_label(i, s.type);
    if (!in_file(s.offset, s.size, size_))
      return fail(ErrorCode::SectionOutOfRange, label + ": bytes [" + std::to_string(s.offset) + ", +" +
                                                    std::to_string(s.size) + ") lie outside the file");
    if (s.offset % GIBAKE_SECTION_ALIGNMENT != 0)
      return fail(ErrorCode::SectionMisaligned, label + ": offset " + std::to_string(s.offset) + " is not 16-aligned");
    if (known_type(s.type)) {
      const uint64_t elem = element_size(s.type, s.format);
      if (!format_allowed(s.type, s.format) || elem == 0)
        return fail(ErrorCode::BadElementFormat, label + ": element format " + std::to_string(s.format) +
                                                     " is not valid for this section type");
      if (s.count > s.size || s.count * elem != s.size)
        return fail(ErrorCode::BadElementFormat, label + ": size " + std::to_string(s.size) + " != count " +
                                                     std::to_string(s.count) + " x " + std::to_string(elem));
    }
  }
  // Reserved in every 1.x, checked once the entries' places and formats hold (those errors say more).
  for (uint32_t i = 0; i < sections_.size(); ++i) {
    const gibake_section_entry& s = sections_[i];
    if (s.flags != 0 || s.reserved[0] != 0 || s.reserved[1] != 0)
      return fail(ErrorCode::BadSectionTable,
                  section_label(i, s.type) + ": flags or reserved words set; 1.x defines none");
  }
  // (An empty table, which validate() puts at or after the header, can overlap nothing.)
  const std::vector<Range> ranges = occupied_ranges(header_, sections_);
  for (size_t i = 1; i < ranges.size(); ++i)
    if (ranges[i].begin < ranges[i - 1].end)
      return fail(ErrorCode::SectionOverlap, ranges[i].label + " overlaps " + ranges[i - 1].label);
  if (options.verify_checksums) {
    for (uint32_t i = 0; i < sections_.size(); ++i) {
      const gibake_section_entry& s = sections_[i];
      if (xxh64(data_ + s.offset, static_cast<size_t>(s.size), GIBAKE_HASH_SEED) != s.checksum)
        return fail(ErrorCode::SectionChecksum, section_label(i, s.type) + ": checksum mismatch");
    }
  }
  return {};
}

}  // namespace gibake::loader
