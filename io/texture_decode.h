// Image decoding for the glTF importer (stb_image, compiled privately in texture_decode.cpp):
// dimensions are read from the header and checked against ImportLimits before any pixels are
// allocated.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "io/import.h"
#include "io/status.h"

namespace gibake::gltf {

struct ImageBudget {
  const ImportLimits* limits = nullptr;
  uint64_t total_pixels = 0;  // decoded so far
  bool decode = true;         // false: header only (dimensions)
};

struct DecodedImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba8;  // width*height*4 when decoded
};

// InvalidInput (file, where) when the header claims dimensions over the limits. A file stb cannot
// read is not an error: `out` stays empty and `warning` says why.
Status decode_image(const unsigned char* bytes, size_t size, const std::string& file,
                    const std::string& where, ImageBudget& budget, DecodedImage& out,
                    std::string& warning);

}  // namespace gibake::gltf
