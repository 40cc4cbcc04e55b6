// Image decoding for the glTF importer (stb_image, compiled privately in texture_decode.cpp), in
// two steps so the pixels can be decoded in parallel: the header is read and checked against
// ImportLimits first (serially, in image order), and only then are pixels allocated and decoded.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "io/gltf/import.h"
#include "io/status.h"

namespace gibake::gltf {

struct ImageBudget {
  const ImportLimits* limits = nullptr;
  uint64_t total_pixels = 0;  // header pixels of the images accepted so far
  bool decode = true;         // false: header only (dimensions), no total-pixel budget
};

struct ImageHeader {
  int width = 0, height = 0;  // 0x0 when the header could not be read
};

// InvalidInput (file, where) when the header claims dimensions over the limits; otherwise the
// image is accepted and, when budget.decode, its pixels count against the total. A file stb cannot
// read is not an error: `out` stays 0x0 and `warning` says why. Not thread-safe (stb's failure
// reason is read here).
Status check_image_header(const unsigned char* bytes, size_t size, const std::string& file, const std::string& where,
                          ImageBudget& budget, ImageHeader& out, std::string& warning);

// Decodes an image accepted by check_image_header to RGBA8 (width*height*4 bytes in `rgba8`):
// common PNGs through io/gltf/png_decode.h's fast path, everything else (and any PNG that path
// declines) through stb, with stb's pixels either way. False, with `rgba8` empty, when stb fails or
// finds other dimensions than the header's. Thread-safe: touches no shared state, so images can be
// decoded concurrently.
bool decode_rgba8(const unsigned char* bytes, size_t size, const ImageHeader& header, std::vector<uint8_t>& rgba8);

// The same through stb alone: the reference the fast path is tested against.
bool decode_rgba8_stb(const unsigned char* bytes, size_t size, const ImageHeader& header, std::vector<uint8_t>& rgba8);

}  // namespace gibake::gltf
