#include "io/gltf/png_decode.h"

#include <libdeflate.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>

namespace gibake::gltf {
namespace {

uint32_t be32(const unsigned char* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

bool chunk_is(const unsigned char* type, const char* name) { return std::memcmp(type, name, 4) == 0; }

// What the chunks say; pointers into the file.
struct PngInfo {
  uint32_t width = 0, height = 0;
  int color_type = -1;
  int channels = 0;
  unsigned char palette[256 * 4];  // entries past palette_entries stay opaque black
  uint32_t palette_entries = 0;
  bool has_trns = false;
  std::vector<std::pair<const unsigned char*, size_t>> idat;
};

int channels_of(int color_type) {
  switch (color_type) {
    case 0:
      return 1;  // grey
    case 2:
      return 3;  // RGB
    case 3:
      return 1;  // palette index
    case 4:
      return 2;  // grey + alpha
    case 6:
      return 4;  // RGBA
    default:
      return 0;
  }
}

bool read_header(const unsigned char* d, uint32_t len, PngInfo& info) {
  if (len != 13) return false;
  info.width = be32(d);
  info.height = be32(d + 4);
  const int depth = d[8], interlace = d[12];
  info.color_type = d[9];
  info.channels = channels_of(info.color_type);
  // Compression and filter method 0 only; 8 bits, no interlace: everything else goes to stb.
  return depth == 8 && interlace == 0 && d[10] == 0 && d[11] == 0 && info.channels > 0;
}

bool read_palette(const unsigned char* d, uint32_t len, PngInfo& info) {
  if (len % 3 != 0 || len > 256 * 3 || len == 0) return false;
  info.palette_entries = len / 3;
  for (uint32_t i = 0; i < 256; ++i) {
    if (i < info.palette_entries)
      std::memcpy(&info.palette[i * 4], d + i * 3, 3);
    else
      std::memset(&info.palette[i * 4], 0, 3);
    info.palette[i * 4 + 3] = 255;
  }
  return true;
}

// Palette alpha only; a colour key on grey or RGB images is left to stb.
bool read_transparency(const unsigned char* d, uint32_t len, PngInfo& info) {
  if (info.color_type != 3 || info.palette_entries == 0 || len > info.palette_entries) return false;
  for (uint32_t i = 0; i < len; ++i) info.palette[i * 4 + 3] = d[i];
  info.has_trns = true;
  return true;
}

bool parse_chunks(const unsigned char* b, size_t size, PngInfo& info) {
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || std::memcmp(b, sig, 8) != 0) return false;
  for (size_t o = 8; o + 12 <= size;) {
    const uint32_t len = be32(b + o);
    const unsigned char* type = b + o + 4;
    const unsigned char* data = b + o + 8;
    if (len > size - o - 12) return false;
    const bool first = o == 8;
    if (first != chunk_is(type, "IHDR")) return false;
    bool ok = true;
    if (first)
      ok = read_header(data, len, info);
    else if (chunk_is(type, "PLTE"))
      ok = info.idat.empty() && read_palette(data, len, info);
    else if (chunk_is(type, "tRNS"))
      ok = info.idat.empty() && read_transparency(data, len, info);
    else if (chunk_is(type, "IDAT"))
      info.idat.emplace_back(data, len);
    else if (chunk_is(type, "IEND"))
      return !info.idat.empty();
    else
      ok = (type[0] & 0x20) != 0;  // unknown critical chunks (CgBI, ...) are stb's to judge
    if (!ok) return false;
    o += 12 + size_t(len);
  }
  return false;  // no IEND
}

// Paeth's predictor (of a, b, c the one nearest to a + b - c; ties to a, then b) in an equivalent
// threshold form that compiles to conditional moves, since photos mix the three choices
// unpredictably. Equivalence is checked against stb on random rows (tests/io/png_decode_test.cpp).
inline int paeth(int a, int b, int c) {
  const int lo = std::min(a, b), hi = std::max(a, b);
  const int thresh = c * 3 - (a + b);
  const int t0 = hi <= thresh ? lo : c;
  return thresh <= lo ? hi : t0;
}

// Reverses one row's filter in place; `up` is the previous reconstructed row (zeros for the first).
// BPP is a constant so each loop unrolls over a pixel's bytes.
template <size_t BPP>
bool unfilter_row(int filter, unsigned char* row, const unsigned char* up, size_t stride) {
  switch (filter) {
    case 0:
      return true;
    // Sub, Average and Paeth depend on the pixel to the left: a pixel at a time, its BPP bytes are
    // independent chains that overlap in the pipeline.
    case 1:
      for (size_t i = BPP; i < stride; i += BPP)
        for (size_t k = 0; k < BPP; ++k) row[i + k] = static_cast<unsigned char>(row[i + k] + row[i + k - BPP]);
      return true;
    case 2:
      for (size_t i = 0; i < stride; ++i) row[i] = static_cast<unsigned char>(row[i] + up[i]);
      return true;
    case 3:
      for (size_t i = 0; i < BPP; ++i) row[i] = static_cast<unsigned char>(row[i] + (up[i] >> 1));
      for (size_t i = BPP; i < stride; i += BPP)
        for (size_t k = 0; k < BPP; ++k)
          row[i + k] = static_cast<unsigned char>(row[i + k] + ((int(row[i + k - BPP]) + int(up[i + k])) >> 1));
      return true;
    case 4:
      for (size_t i = 0; i < BPP; ++i) row[i] = static_cast<unsigned char>(row[i] + up[i]);
      for (size_t i = BPP; i < stride; i += BPP)
        for (size_t k = 0; k < BPP; ++k)
          row[i + k] = static_cast<unsigned char>(row[i + k] + paeth(row[i + k - BPP], up[i + k], up[i + k - BPP]));
      return true;
    default:
      return false;
  }
}

bool unfilter_row(int filter, unsigned char* row, const unsigned char* up, size_t stride, size_t bpp) {
  switch (bpp) {
    case 1:
      return unfilter_row<1>(filter, row, up, stride);
    case 2:
      return unfilter_row<2>(filter, row, up, stride);
    case 3:
      return unfilter_row<3>(filter, row, up, stride);
    case 4:
      return unfilter_row<4>(filter, row, up, stride);
    default:
      return false;
  }
}

// One reconstructed row into RGBA8.
void expand_row(const PngInfo& info, const unsigned char* row, unsigned char* out) {
  const uint32_t w = info.width;
  switch (info.color_type) {
    case 0:
      for (uint32_t x = 0; x < w; ++x, out += 4) out[0] = out[1] = out[2] = row[x], out[3] = 255;
      return;
    case 2:
      for (uint32_t x = 0; x < w; ++x, out += 4, row += 3)
        out[0] = row[0], out[1] = row[1], out[2] = row[2], out[3] = 255;
      return;
    case 3:
      for (uint32_t x = 0; x < w; ++x, out += 4) std::memcpy(out, &info.palette[row[x] * 4], 4);
      return;
    case 4:
      for (uint32_t x = 0; x < w; ++x, out += 4, row += 2) out[0] = out[1] = out[2] = row[0], out[3] = row[1];
      return;
    case 6:
      std::memcpy(out, row, size_t(w) * 4);
      return;
    default:
      return;
  }
}

// The IDAT chunks as one zlib stream, inflated to exactly `raw_size` bytes.
bool inflate_idat(const PngInfo& info, unsigned char* raw, size_t raw_size) {
  std::vector<unsigned char> joined;
  const unsigned char* in = info.idat[0].first;
  size_t in_size = info.idat[0].second;
  if (info.idat.size() > 1) {
    size_t total = 0;
    for (const auto& c : info.idat) total += c.second;
    joined.reserve(total);
    for (const auto& c : info.idat) joined.insert(joined.end(), c.first, c.first + c.second);
    in = joined.data();
    in_size = joined.size();
  }
  std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)> d(libdeflate_alloc_decompressor(),
                                                                                 libdeflate_free_decompressor);
  // Exact size: a short stream, extra data or a bad checksum all go to stb, which decides.
  return d && libdeflate_zlib_decompress(d.get(), in, in_size, raw, raw_size, nullptr) == LIBDEFLATE_SUCCESS;
}

}  // namespace

bool decode_png_fast(const unsigned char* bytes, size_t size, int width, int height, std::vector<uint8_t>& rgba8) {
  PngInfo info;
  if (bytes == nullptr || !parse_chunks(bytes, size, info)) return false;
  if (width <= 0 || height <= 0 || info.width != uint32_t(width) || info.height != uint32_t(height)) return false;
  if (info.color_type == 3 && info.palette_entries == 0) return false;
  const size_t bpp = size_t(info.channels);
  const size_t stride = size_t(info.width) * bpp;
  const size_t raw_size = (stride + 1) * info.height;
  std::unique_ptr<unsigned char[]> raw(new unsigned char[raw_size]);  // no zero-fill: inflate writes it all
  if (!inflate_idat(info, raw.get(), raw_size)) return false;
  rgba8.resize(size_t(info.width) * info.height * 4);
  const std::vector<unsigned char> zero_row(stride, 0);
  const unsigned char* up = zero_row.data();
  for (uint32_t y = 0; y < info.height; ++y) {
    unsigned char* row = raw.get() + size_t(y) * (stride + 1);
    if (!unfilter_row(row[0], row + 1, up, stride, bpp)) return false;
    expand_row(info, row + 1, rgba8.data() + size_t(y) * info.width * 4);
    up = row + 1;
  }
  return true;
}

PalettePad pad_palette_for_stb(const unsigned char* bytes, size_t size, std::vector<unsigned char>& padded) {
  padded.clear();
  // Walks the chunks as stb does; where the file ends early or is odd, the rest is copied unchanged
  // and stb finds the fault itself.
  if (bytes == nullptr || size < 8 + 25 || be32(bytes + 8) != 13 || !chunk_is(bytes + 12, "IHDR") || bytes[25] != 3)
    return PalettePad::not_needed;
  padded.reserve(size + 768);
  padded.assign(bytes, bytes + 8);
  uint32_t entries = 0;  // of the latest PLTE, before padding
  size_t o = 8;
  for (; o + 12 <= size; ) {
    const uint32_t len = be32(bytes + o);
    if (len > size - o - 12) break;
    const unsigned char* type = bytes + o + 4;
    if (chunk_is(type, "PLTE") && len > 0 && len <= 768 && len % 3 == 0) {
      entries = len / 3;
      const unsigned char head[8] = {0, 0, 3, 0, 'P', 'L', 'T', 'E'};
      const size_t at = padded.size();
      padded.insert(padded.end(), head, head + 8);
      padded.insert(padded.end(), bytes + o + 8, bytes + o + 8 + len);
      padded.resize(padded.size() + (768 - len), 0);
      const uint32_t crc = libdeflate_crc32(0, padded.data() + at + 4, 4 + 768);
      for (int s = 24; s >= 0; s -= 8) padded.push_back(static_cast<unsigned char>(crc >> s));
    } else {
      if (chunk_is(type, "tRNS") && entries > 0 && len > entries) {
        padded.clear();
        return PalettePad::refused;
      }
      padded.insert(padded.end(), bytes + o, bytes + o + 12 + len);
    }
    o += 12 + size_t(len);
  }
  padded.insert(padded.end(), bytes + o, bytes + size);
  return PalettePad::padded;
}

bool png_chunks_fit(const unsigned char* bytes, size_t size) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || std::memcmp(bytes, kSignature, 8) != 0) return true;
  size_t pos = 8;
  while (pos + 12 <= size) {
    const uint32_t length = uint32_t(bytes[pos]) << 24 | uint32_t(bytes[pos + 1]) << 16 |
                            uint32_t(bytes[pos + 2]) << 8 | uint32_t(bytes[pos + 3]);
    if (length > size - pos - 12) return false;  // data and CRC run past the end
    if (chunk_is(bytes + pos + 4, "IEND")) return true;
    pos += 12 + size_t(length);
  }
  return pos == size;  // no partial chunk header left over
}

}  // namespace gibake::gltf
