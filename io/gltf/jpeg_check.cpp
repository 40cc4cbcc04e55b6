#include "io/gltf/jpeg_check.h"

namespace gibake::gltf {
namespace {

constexpr int kNoMarker = -1;

bool is_restart(int m) { return m >= 0xD0 && m <= 0xD7; }

// Markers followed by a 16-bit length: SOFn and DHT (C0-CF), SOS, DQT, DNL, DRI, DHP, EXP (DA-DF),
// APPn (E0-EF), COM (FE). stb stops at every other marker, so the walk does too.
bool has_length(int m) { return (m >= 0xC0 && m <= 0xCF) || (m >= 0xDA && m <= 0xDF) || (m >= 0xE0 && m <= 0xEF) || m == 0xFE; }

bool is_frame_start(int m) { return m == 0xC0 || m == 0xC1 || m == 0xC2; }

// stb's marker read at `p`: a byte other than 0xFF is no marker; fill 0xFF bytes are skipped.
int read_marker(const unsigned char* b, size_t size, size_t& p) {
  if (p >= size || b[p] != 0xFF) return kNoMarker;
  while (p < size && b[p] == 0xFF) ++p;
  if (p >= size) return kNoMarker;
  return b[p++];
}

// The tables of one DHT segment's body (after its length field).
bool huffman_tables_sound(const unsigned char* d, size_t len) {
  for (size_t o = 0; o < len;) {
    if (len - o < 17) return false;
    const int table_class = d[o] >> 4, table_id = d[o] & 15;
    if (table_class > 1 || table_id > 3) return false;
    size_t codes = 0;
    for (int i = 1; i <= 16; ++i) codes += d[o + i];
    if (codes > 256 || codes > len - o - 17) return false;
    o += 17 + codes;
  }
  return true;
}

// From just after an SOS segment to the first byte of the next marker (0xFF) that ends the scan.
size_t skip_entropy_data(const unsigned char* b, size_t size, size_t p) {
  while (p < size) {
    if (b[p] != 0xFF) {
      ++p;
      continue;
    }
    size_t q = p;
    while (q < size && b[q] == 0xFF) ++q;
    if (q >= size) return size;
    if (b[q] != 0x00 && !is_restart(b[q])) return p;
    p = q + 1;
  }
  return size;
}

}  // namespace

bool jpeg_segments_fit(const unsigned char* bytes, size_t size) {
  if (bytes == nullptr) return true;
  size_t p = 0;
  if (read_marker(bytes, size, p) != 0xD8) return true;  // not a JPEG
  bool in_frame = false;
  while (p < size) {
    if (bytes[p] != 0xFF) {
      if (in_frame) return true;  // stb wants a marker here and stops
      ++p;                        // before the frame stb scans on for the next marker
      continue;
    }
    const int m = read_marker(bytes, size, p);
    if (m == kNoMarker || !has_length(m)) return true;  // EOI, or a marker stb stops at
    if (size - p < 2) return false;
    const size_t len = size_t(bytes[p]) << 8 | bytes[p + 1];
    if (len < 2 || len > size - p) return false;
    if (m == 0xC4 && !huffman_tables_sound(bytes + p + 2, len - 2)) return false;
    p += len;
    if (is_frame_start(m)) in_frame = true;
    if (m == 0xDA) p = skip_entropy_data(bytes, size, p);
  }
  return true;
}

}  // namespace gibake::gltf
