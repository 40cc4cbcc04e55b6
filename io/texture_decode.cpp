// stb_image lives here, static, so no other library's copy can clash with ours.
#include "io/texture_decode.h"

#include <climits>
#include <cstring>

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
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace gibake::gltf {
namespace {

Status check_dims(int w, int h, const std::string& file, const std::string& where,
                  const ImageBudget& budget) {
  const ImportLimits& lim = *budget.limits;
  if (w <= 0 || h <= 0) return Status::invalid(file, where, "image has no pixels");
  if (uint64_t(w) > lim.max_image_dimension || uint64_t(h) > lim.max_image_dimension)
    return Status::invalid(file, where,
                           "image is " + std::to_string(w) + "x" + std::to_string(h) +
                               ", over the limit of " + std::to_string(lim.max_image_dimension) +
                               " per side");
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
  auto be = [b](size_t o) { return uint32_t(b[o]) << 24 | uint32_t(b[o + 1]) << 16 | uint32_t(b[o + 2]) << 8 | b[o + 3]; };
  w = be(16);
  h = be(20);
  return true;
}

}  // namespace

Status decode_image(const unsigned char* bytes, size_t size, const std::string& file,
                    const std::string& where, ImageBudget& budget, DecodedImage& out,
                    std::string& warning) {
  out = DecodedImage();
  if (bytes == nullptr || size == 0 || size > size_t(INT_MAX)) {
    warning = where + ": empty or oversized image data";
    return Status::ok();
  }
  uint32_t pw = 0, ph = 0;
  if (png_dimensions(bytes, size, pw, ph) && (pw > budget.limits->max_image_dimension || ph > budget.limits->max_image_dimension))
    return Status::invalid(file, where, "image is " + std::to_string(pw) + "x" + std::to_string(ph) +
                                            ", over the limit of " + std::to_string(budget.limits->max_image_dimension) +
                                            " per side");
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(bytes, int(size), &w, &h, &comp)) {
    if (std::string(stbi_failure_reason()) == "too large")
      return Status::invalid(file, where, "image header claims dimensions too large to decode");
    warning = where + ": unsupported or corrupt image (" + std::string(stbi_failure_reason()) + ")";
    return Status::ok();
  }
  GIBAKE_TRY(check_dims(w, h, file, where, budget));
  out.width = w;
  out.height = h;
  if (!budget.decode) return Status::ok();
  int dw = 0, dh = 0;
  stbi_uc* px = stbi_load_from_memory(bytes, int(size), &dw, &dh, &comp, 4);
  if (px == nullptr || dw != w || dh != h) {
    if (px) stbi_image_free(px);
    warning = where + ": image could not be decoded";
    out = DecodedImage();
    return Status::ok();
  }
  out.rgba8.assign(px, px + size_t(w) * size_t(h) * 4);
  stbi_image_free(px);
  budget.total_pixels += uint64_t(w) * uint64_t(h);
  return Status::ok();
}

}  // namespace gibake::gltf
