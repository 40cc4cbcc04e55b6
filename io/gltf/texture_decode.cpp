// stb_image lives here, static, so no other library's copy can clash with ours.
#include "io/gltf/texture_decode.h"

#include <climits>
#include <cstring>

#include "io/gltf/jpeg_check.h"
#include "io/gltf/png_decode.h"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO
#define STBI_MAX_DIMENSIONS 65536
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#if defined(__GNUC__) && !defined(__clang__)
// Inlined into decode_rgba8, stb's memory-reader context looks half-initialized to GCC (the
// callback fields are never read for memory input).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace gibake::gltf {
namespace {

Status over_side_limit(uint64_t w, uint64_t h, const std::string& file, const std::string& where,
                       const ImportLimits& lim) {
  return Status::invalid(file, where,
                         "image is " + std::to_string(w) + "x" + std::to_string(h) + ", over the limit of " +
                             std::to_string(lim.max_image_dimension) + " per side");
}

Status check_dims(int w, int h, const std::string& file, const std::string& where, const ImageBudget& budget) {
  const ImportLimits& lim = *budget.limits;
  if (w <= 0 || h <= 0) return Status::invalid(file, where, "image has no pixels");
  if (uint64_t(w) > lim.max_image_dimension || uint64_t(h) > lim.max_image_dimension)
    return over_side_limit(uint64_t(w), uint64_t(h), file, where, lim);
  uint64_t px = uint64_t(w) * uint64_t(h);
  if (px > lim.max_image_pixels)
    return Status::invalid(file, where, "image has " + std::to_string(px) + " pixels, over the limit");
  if (budget.decode && budget.total_pixels + px > lim.max_total_pixels)
    return Status::invalid(file, where, "all images together exceed the pixel limit");
  return Status::ok();
}

// PNG dimensions straight from IHDR: stb refuses huge claims with a soft failure we could not tell
// from a corrupt file, so they are checked here first.
bool png_dimensions(const unsigned char* b, size_t size, uint32_t& w, uint32_t& h) {
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 24 || std::memcmp(b, sig, 8) != 0 || std::memcmp(b + 12, "IHDR", 4) != 0) return false;
  auto be = [b](size_t o) {
    return uint32_t(b[o]) << 24 | uint32_t(b[o + 1]) << 16 | uint32_t(b[o + 2]) << 8 | b[o + 3];
  };
  w = be(16);
  h = be(20);
  return true;
}

Status check_png_sides(const unsigned char* bytes, size_t size, const std::string& file, const std::string& where,
                       const ImportLimits& lim) {
  uint32_t w = 0, h = 0;
  if (!png_dimensions(bytes, size, w, h)) return Status::ok();
  if (w > lim.max_image_dimension || h > lim.max_image_dimension) return over_side_limit(w, h, file, where, lim);
  return Status::ok();
}

}  // namespace

Status check_image_header(const unsigned char* bytes, size_t size, const std::string& file, const std::string& where,
                          ImageBudget& budget, ImageHeader& out, std::string& warning) {
  out = ImageHeader();
  if (bytes == nullptr || size == 0 || size > size_t(INT_MAX)) {
    warning = where + ": empty or oversized image data";
    return Status::ok();
  }
  GIBAKE_TRY(check_png_sides(bytes, size, file, where, *budget.limits));
  if (!jpeg_segments_fit(bytes, size)) {  // stbi_info already builds Huffman tables
    warning = where + ": unsupported or corrupt image (JPEG marker segment runs past the file or "
                      "has a malformed Huffman table)";
    return Status::ok();
  }
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(bytes, int(size), &w, &h, &comp)) {
    if (std::string(stbi_failure_reason()) == "too large")
      return Status::invalid(file, where, "image header claims dimensions too large to decode");
    warning = where + ": unsupported or corrupt image (" + std::string(stbi_failure_reason()) + ")";
    return Status::ok();
  }
  GIBAKE_TRY(check_dims(w, h, file, where, budget));
  // Counted at acceptance, before decoding, so the budget follows image order however the
  // decodes are scheduled later.
  if (budget.decode) budget.total_pixels += uint64_t(w) * uint64_t(h);
  out.width = w;
  out.height = h;
  return Status::ok();
}

bool decode_rgba8(const unsigned char* bytes, size_t size, const ImageHeader& header, std::vector<uint8_t>& rgba8) {
  rgba8.clear();
  if (bytes == nullptr || size == 0 || size > size_t(INT_MAX)) return false;
  if (decode_png_fast(bytes, size, header.width, header.height, rgba8)) return true;
  return decode_rgba8_stb(bytes, size, header, rgba8);
}

bool decode_rgba8_stb(const unsigned char* bytes, size_t size, const ImageHeader& header, std::vector<uint8_t>& rgba8) {
  rgba8.clear();
  if (bytes == nullptr || size == 0 || size > size_t(INT_MAX)) return false;
  if (!png_chunks_fit(bytes, size)) return false;  // stb would allocate what a chunk declares
  if (!jpeg_segments_fit(bytes, size)) return false;  // stb would overrun its Huffman arrays
  std::vector<unsigned char> padded;
  const PalettePad pad = pad_palette_for_stb(bytes, size, padded);
  if (pad == PalettePad::refused) return false;
  if (pad == PalettePad::padded) {
    if (padded.size() > size_t(INT_MAX)) return false;
    bytes = padded.data();
    size = padded.size();
  }
  int w = 0, h = 0, comp = 0;
  stbi_uc* px = stbi_load_from_memory(bytes, int(size), &w, &h, &comp, 4);
  bool ok = px != nullptr && w == header.width && h == header.height;
  if (ok) rgba8.assign(px, px + size_t(w) * size_t(h) * 4);
  if (px) stbi_image_free(px);
  return ok;
}

}  // namespace gibake::gltf
