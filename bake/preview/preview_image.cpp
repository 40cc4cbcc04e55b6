// Preview images: tonemap, PNG (stb_image_write) and EXR (OpenEXR) output, difference images.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>

#include "bake/preview/preview.h"
#include "io/output/bake_atomic.h"
#include "kernels/vec.h"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wcast-qual"
#pragma GCC diagnostic ignored "-Wuseless-cast"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace gibake {
namespace {

using kernels::luminance;

uint8_t to8(float v) { return uint8_t(std::lround(std::clamp(v, 0.f, 1.f) * 255.f)); }

float srgb_encode(float v) {
  v = std::clamp(v, 0.f, 1.f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}
float srgb_decode(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

float aces_fit(float x) {
  x = std::max(x, 0.f);
  return std::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.f, 1.f);
}

bool has_overlay(const PreviewImage& img, size_t i) { return !img.overlay.empty() && (img.overlay[i] >> 24) != 0u; }

std::string lower_ext(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return "";
  std::string e = path.substr(dot);
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// A reference keeps the mean of its first half of samples beside its own (kChannels 3-5) and its
// samples a pixel (kSppAttribute), so that a comparison read from the file later still knows the
// reference's own noise.
constexpr const char* kChannels[6] = {"R", "G", "B", "half.R", "half.G", "half.B"};
constexpr const char* kSppAttribute = "gibakeSpp";

Status write_exr(const std::string& path, const PreviewImage& img, const std::vector<std::string>& inputs) {
  const size_t n = size_t(img.width) * size_t(img.height);
  const bool halves = img.mode == PreviewMode::Reference && img.first_half_rgb.size() == n * 3;
  std::vector<float> planes[6];
  for (int k = 0; k < (halves ? 6 : 3); ++k) planes[k].resize(n);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      float v = img.rgb[i * 3 + size_t(k)];
      if (has_overlay(img, i)) v = srgb_decode(float((img.overlay[i] >> (8 * k)) & 0xFFu) / 255.f);
      planes[k][i] = v;
      if (halves) planes[3 + k][i] = img.first_half_rgb[i * 3 + size_t(k)];
    }
  AtomicFile file;
  GIBAKE_TRY(file.begin(path, inputs));
  try {
    Imf::Header header(img.width, img.height);
    const int channels = halves ? 6 : 3;
    for (int k = 0; k < channels; ++k) header.channels().insert(kChannels[k], Imf::Channel(Imf::FLOAT));
    if (halves) header.insert(kSppAttribute, Imf::IntAttribute(img.spp));
    Imf::OutputFile exr(file.temp_path().c_str(), header);
    Imf::FrameBuffer frame;
    for (int k = 0; k < channels; ++k)
      frame.insert(kChannels[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes[k].data()), sizeof(float),
                                            sizeof(float) * size_t(img.width)));
    exr.setFrameBuffer(frame);
    exr.writePixels(img.height);
  } catch (const std::exception& e) {
    return Status::io(path, std::string("OpenEXR: ") + e.what());
  }
  return file.commit();
}

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* p = static_cast<const uint8_t*>(data);
  out->insert(out->end(), p, p + size);
}

}  // namespace

float auto_ev100(const PreviewImage& img) {
  double log_sum = 0.0;
  size_t count = 0;
  const size_t n = size_t(img.width) * size_t(img.height);
  for (size_t i = 0; i < n; ++i) {
    if (has_overlay(img, i)) continue;
    const float y = luminance(&img.rgb[i * 3]);
    if (y > 0.f && std::isfinite(y)) {
      log_sum += std::log(double(y));
      ++count;
    }
  }
  if (count == 0) return 0.f;
  const double avg = std::exp(log_sum / double(count));
  return float(std::log2(avg * 100.0 / 12.5));
}

std::vector<uint8_t> tonemap_rgb8(const PreviewImage& img, const Tonemap& tm, float* ev_used) {
  const size_t n = size_t(img.width) * size_t(img.height);
  std::vector<uint8_t> out(n * 3);
  const float ev = tm.auto_exposure ? auto_ev100(img) : tm.ev100;
  if (ev_used) *ev_used = img.tonemapped() ? ev : 0.f;
  const float scale = 1.f / (1.2f * std::exp2(ev));
  for (size_t i = 0; i < n; ++i) {
    if (has_overlay(img, i)) {
      for (int k = 0; k < 3; ++k) out[i * 3 + size_t(k)] = uint8_t((img.overlay[i] >> (8 * k)) & 0xFFu);
      continue;
    }
    for (size_t k = 0; k < 3; ++k) {
      const float v = img.rgb[i * 3 + k];
      float d;
      if (img.mode == PreviewMode::Normals) d = v;
      else if (img.mode == PreviewMode::Albedo) d = srgb_encode(v);
      else d = srgb_encode(aces_fit(std::isfinite(v) ? v * scale : 0.f));
      out[i * 3 + k] = to8(d);
    }
  }
  return out;
}

Status encode_png(int width, int height, const std::vector<uint8_t>& rgb8, std::vector<uint8_t>& png) {
  png.clear();
  if (width < 1 || height < 1 || rgb8.size() != size_t(width) * size_t(height) * 3)
    return Status::error(ExitCode::RuntimeFailure, "", "png", "image size does not match its pixels");
  if (!stbi_write_png_to_func(append_bytes, &png, width, height, 3, rgb8.data(), width * 3))
    return Status::error(ExitCode::RuntimeFailure, "", "png", "stb_image_write failed to encode the image");
  return Status::ok();
}

Status write_preview(const std::string& path, const PreviewImage& img, const Tonemap& tm,
                     const std::vector<std::string>& inputs, float* ev_used) {
  const std::string ext = lower_ext(path);
  if (ext == ".exr") {
    if (ev_used) *ev_used = 0.f;
    return write_exr(path, img, inputs);
  }
  if (ext != ".png")
    return Status::error(ExitCode::BadArguments, path, "--out", "expected a .png or .exr file name");
  std::vector<uint8_t> png;
  GIBAKE_TRY(encode_png(img.width, img.height, tonemap_rgb8(img, tm, ev_used), png));
  Status st = write_file_atomic(path, png.data(), png.size(), inputs);
  return st;
}

Status read_reference_exr(const std::string& path, int width, int height, PreviewImage& out) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return Status::io(path, "cannot open the reference image");
  if (!S_ISREG(st.st_mode)) return Status::invalid(path, "reference image", "not a regular file");
  out = PreviewImage{};
  try {
    Imf::InputFile exr(path.c_str());
    const Imf::Header& header = exr.header();
    const Imath::Box2i window = header.dataWindow();
    const int64_t wide = int64_t(window.max.x) - window.min.x + 1, high = int64_t(window.max.y) - window.min.y + 1;
    if (wide != width || high != height)
      return Status::invalid(path, "data window",
                             std::to_string(wide) + "x" + std::to_string(high) + " pixels where the view has " +
                                 std::to_string(width) + "x" + std::to_string(height) + " (--size)");
    for (const char* name : {"R", "G", "B"})
      if (!header.channels().findChannel(name))
        return Status::invalid(path, "channels", std::string("no channel ") + name + " (linear RGB in cd/m^2)");
    bool halves = true;
    for (int k = 3; k < 6; ++k) halves = halves && header.channels().findChannel(kChannels[k]);
    const Imf::IntAttribute* spp = header.findTypedAttribute<Imf::IntAttribute>(kSppAttribute);
    halves = halves && spp && spp->value() >= 2;
    const size_t n = size_t(width) * size_t(height);
    std::vector<float> planes[6];
    Imf::FrameBuffer frame;
    for (int k = 0; k < (halves ? 6 : 3); ++k) {
      planes[k].assign(n, 0.f);
      // Slices are addressed from the data window's origin, wherever it lies.
      char* base = reinterpret_cast<char*>(planes[k].data()) -
                   (ptrdiff_t(window.min.x) + ptrdiff_t(window.min.y) * ptrdiff_t(width)) * ptrdiff_t(sizeof(float));
      frame.insert(kChannels[k], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * size_t(width)));
    }
    exr.setFrameBuffer(frame);
    exr.readPixels(window.min.y, window.max.y);
    out.width = width;
    out.height = height;
    out.mode = PreviewMode::Reference;
    out.rgb.resize(n * 3);
    if (halves) out.first_half_rgb.resize(n * 3);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < (halves ? 6 : 3); ++k) {
        const float v = planes[k][i];
        if (!std::isfinite(v) || v < 0.f)
          return Status::invalid(path,
                                 "pixel " + std::to_string(i % size_t(width)) + "," +
                                     std::to_string(i / size_t(width)) + " channel " + kChannels[k],
                                 "not a finite, non-negative value");
        (k < 3 ? out.rgb : out.first_half_rgb)[i * 3 + size_t(k % 3)] = v;
      }
    out.spp = halves ? spp->value() : 0;
  } catch (const std::exception& e) {
    return Status::invalid(path, "OpenEXR", e.what());
  }
  return Status::ok();
}

Status diff_previews(const PreviewImage& test, const PreviewImage& ref, float floor_fraction, PreviewDiff& diff,
                     std::vector<uint8_t>* false_colour) {
  if (test.width != ref.width || test.height != ref.height)
    return Status::error(ExitCode::RuntimeFailure, "", "--diff", "images differ in size");
  const size_t n = size_t(ref.width) * size_t(ref.height);
  double mean = 0.0;
  for (size_t i = 0; i < n; ++i) mean += double(luminance(&ref.rgb[i * 3]));
  mean /= double(std::max<size_t>(n, 1));
  diff = PreviewDiff();
  diff.floor = float(mean) * floor_fraction;
  double num = 0.0, den = 0.0, rel = 0.0;
  if (false_colour) false_colour->assign(n * 3, 0);
  for (size_t i = 0; i < n; ++i) {
    const double yr = luminance(&ref.rgb[i * 3]), yt = luminance(&test.rgb[i * 3]);
    uint8_t c[3] = {40, 40, 40};
    if (yr > diff.floor && std::isfinite(yt) && std::isfinite(yr)) {
      num += (yt - yr) * (yt - yr);
      den += yr * yr;
      rel += std::fabs(yt - yr) / yr;
      ++diff.pixels;
      const float r = float(std::clamp((yt - yr) / yr / 0.5, -1.0, 1.0));  // +-50% saturates
      // Diverging: blue (under) -> white -> red (over), in display values.
      if (r >= 0.f) {
        c[0] = 255;
        c[1] = c[2] = to8(1.f - r);
      } else {
        c[2] = 255;
        c[0] = c[1] = to8(1.f + r);
      }
    }
    if (false_colour)
      for (size_t k = 0; k < 3; ++k) (*false_colour)[i * 3 + k] = c[k];
  }
  diff.rms = den > 0.0 ? std::sqrt(num / den) : 0.0;
  diff.mean_abs_relative = diff.pixels ? rel / double(diff.pixels) : 0.0;
  return Status::ok();
}

std::string base64_encode(const std::vector<uint8_t>& bytes) {
  static const char* const table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = uint32_t(bytes[i]) << 16 | uint32_t(bytes[i + 1]) << 8 | bytes[i + 2];
    for (int s = 18; s >= 0; s -= 6) out += table[(v >> s) & 63u];
  }
  if (i < bytes.size()) {
    uint32_t v = uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
    out += table[(v >> 18) & 63u];
    out += table[(v >> 12) & 63u];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63u] : '=';
    out += '=';
  }
  return out;
}

}  // namespace gibake
