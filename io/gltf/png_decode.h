// A fast path for the PNGs glTF scenes carry: 8-bit, non-interlaced grey, grey+alpha, RGB, RGBA and
// palette images, inflated in one call by libdeflate (about 3x faster than stb_image's own inflate,
// which was most of Sponza's import). Anything else, and any file this path finds odd, is left to
// stb_image, so the pixels are always the ones stb would give.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace gibake::gltf {

// Decodes `bytes` into width*height RGBA8 pixels. False (and `rgba8` unspecified) when the image is
// not one this path handles or does not match the expected size: the caller falls back to stb.
bool decode_png_fast(const unsigned char* bytes, size_t size, int width, int height, std::vector<uint8_t>& rgba8);

}  // namespace gibake::gltf
