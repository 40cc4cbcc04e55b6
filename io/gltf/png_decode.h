// A fast path for the PNGs glTF scenes carry: 8-bit, non-interlaced grey, grey+alpha, RGB, RGBA and
// palette images, inflated in one call by libdeflate (faster than stb_image's own inflate, which
// dominates the import of texture-heavy scenes; docs/BENCHMARKS.md). Anything else, and any file
// this path finds odd, is left to stb_image, so the pixels are always the ones stb would give.
//
// One rule is ours, not stb's: a palette index past the PLTE chunk's entries reads opaque black
// (libpng's rule). stb would read those entries from an uninitialised array, so the same file could
// decode to different pixels from run to run; pad_palette_for_stb gives stb the same rule.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace gibake::gltf {

// Decodes `bytes` into width*height RGBA8 pixels. False (and `rgba8` unspecified) when the image is
// not one this path handles or does not match the expected size: the caller falls back to stb.
bool decode_png_fast(const unsigned char* bytes, size_t size, int width, int height, std::vector<uint8_t>& rgba8);

enum class PalettePad { not_needed, padded, refused };

// For a colour-type-3 PNG, a copy whose well-formed PLTE chunks hold 256 entries, the ones past the
// original count black (stb then makes them opaque): an out-of-range index decodes the same way
// every time. `refused` when a tRNS chunk is longer than its palette, which stb refuses too and the
// padding would hide. `not_needed` (and `padded` left empty) for every other image.
PalettePad pad_palette_for_stb(const unsigned char* bytes, size_t size, std::vector<unsigned char>& padded);

// For a PNG (by its signature), whether every chunk's declared length fits in the bytes that follow
// it. stb_image grows its IDAT buffer to a chunk's declared length before reading it, so a small
// file declaring a huge IDAT would make it allocate gigabytes; such a file is refused before stb
// sees it. True for anything that is not a PNG.
bool png_chunks_fit(const unsigned char* bytes, size_t size);

}  // namespace gibake::gltf
