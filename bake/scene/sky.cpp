#include "bake/scene/sky.h"

#include <OpenEXR/ImfArray.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfRgbaFile.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>

namespace gibake {
using kernels::float3;

float3 Sky::radiance(const float3& d) const {
  if (rgb.empty() || width <= 0 || height <= 0) return constant * scale;
  const float u = 0.5f + std::atan2(d.x, -d.z) / (2.f * kernels::kPi);
  const float v = std::acos(kernels::clampf(d.y, -1.f, 1.f)) / kernels::kPi;
  const float x = u * width - 0.5f, y = v * height - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  auto wrapx = [&](int i) { i %= width; return i < 0 ? i + width : i; };
  auto clampy = [&](int i) { return i < 0 ? 0 : (i >= height ? height - 1 : i); };
  float3 out{};
  const int xs[2] = {wrapx(x0), wrapx(x0 + 1)}, ys[2] = {clampy(y0), clampy(y0 + 1)};
  const float wx[2] = {1.f - ax, ax}, wy[2] = {1.f - ay, ay};
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) out += kernels::load3(&rgb[(size_t(ys[j]) * width + xs[i]) * 3]) * (wx[i] * wy[j]);
  return out * scale;
}

namespace {
// Index of the first prefix sum above u (the last when rounding leaves none), and u's place in it.
int pick(const float* cdf, int n, float u, float& frac, float& p) {
  const int i = std::min(int(std::upper_bound(cdf, cdf + n, u) - cdf), n - 1);
  const float lo = i > 0 ? cdf[i - 1] : 0.f;
  p = cdf[i] - lo;
  frac = p > 0.f ? std::min((u - lo) / p, 0.99999994f) : 0.5f;
  return i;
}
}  // namespace

void build_sky_sampling(Sky& sky) {
  sky.row_cdf.clear();
  sky.col_cdf.clear();
  const int w = sky.width, h = sky.height;
  if (sky.rgb.empty() || w <= 0 || h <= 0) return;
  std::vector<double> rows(static_cast<size_t>(h));
  std::vector<float> cols(size_t(w) * h);
  double total = 0.0;
  for (int y = 0; y < h; ++y) {
    const double s = std::sin(kernels::kPi * (y + 0.5) / h);
    double run = 0.0;
    std::vector<double> row(static_cast<size_t>(w));
    for (int x = 0; x < w; ++x) {
      // The bilinear lookup blends a cell with its 8 neighbours (wrapping in u, clamped in v): their
      // largest luminance bounds the radiance anywhere in it, so no sample's weight can explode.
      double lum = 0.0;
      for (int j = std::max(0, y - 1); j <= std::min(h - 1, y + 1); ++j)
        for (int i = x - 1; i <= x + 1; ++i) {
          const float* c = &sky.rgb[(size_t(j) * w + size_t((i + w) % w)) * 3];
          lum = std::max(lum, 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]);
        }
      run += lum * s;
      row[size_t(x)] = run;
    }
    for (int x = 0; x < w; ++x) cols[size_t(y) * w + x] = run > 0.0 ? float(row[size_t(x)] / run) : float(x + 1) / w;
    cols[size_t(y) * w + w - 1] = 1.f;
    rows[size_t(y)] = run;
    total += run;
  }
  if (!(total > 0.0) || !std::isfinite(total)) return;
  sky.row_cdf.resize(size_t(h));
  double run = 0.0;
  for (int y = 0; y < h; ++y) {
    run += rows[size_t(y)];
    sky.row_cdf[size_t(y)] = float(run / total);
  }
  sky.row_cdf.back() = 1.f;
  sky.col_cdf = std::move(cols);
}

float3 Sky::sample(float u_row, float u_col, float& pdf) const {
  float fy, fx, p_row, p_col;
  const int y = pick(row_cdf.data(), height, u_row, fy, p_row);
  const int x = pick(&col_cdf[size_t(y) * width], width, u_col, fx, p_col);
  const float u = (float(x) + fx) / float(width), v = (float(y) + fy) / float(height);
  const float theta = kernels::kPi * v, phi = 2.f * kernels::kPi * (u - 0.5f);
  const float st = std::sin(theta);
  pdf = st > 0.f ? p_row * p_col * float(width) * float(height) / (2.f * kernels::kPi * kernels::kPi * st) : 0.f;
  return {st * std::sin(phi), std::cos(theta), -st * std::cos(phi)};
}

float Sky::pdf(const float3& d) const {
  if (!sampled()) return 0.f;
  const float u = 0.5f + std::atan2(d.x, -d.z) / (2.f * kernels::kPi);
  const float v = std::acos(kernels::clampf(d.y, -1.f, 1.f)) / kernels::kPi;
  const int x = std::clamp(int(u * float(width)), 0, width - 1), y = std::clamp(int(v * float(height)), 0, height - 1);
  const float p_row = row_cdf[size_t(y)] - (y > 0 ? row_cdf[size_t(y) - 1] : 0.f);
  const float* c = &col_cdf[size_t(y) * width];
  const float p_col = c[x] - (x > 0 ? c[x - 1] : 0.f);
  const float st = std::sqrt(std::max(0.f, 1.f - d.y * d.y));
  return st > 0.f ? p_row * p_col * float(width) * float(height) / (2.f * kernels::kPi * kernels::kPi * st) : 0.f;
}

bool Sky::is_black() const {
  if (scale <= 0.f) return true;
  if (rgb.empty()) return constant.x <= 0.f && constant.y <= 0.f && constant.z <= 0.f;
  for (float c : rgb)
    if (c > 0.f) return false;
  return true;
}

namespace {

// The map's pixels as floats, R, G and B read at full precision where the file has them (a sunlit
// sky's sun lies far above a half float's 65504), else through OpenEXR's RGBA interface (Y or YC
// files). False: none of R, G, B or Y, which would read as a black sky.
bool read_sky_pixels(const std::string& path, int& w, int& h, std::vector<float>& rgb) {
  Imf::InputFile file(path.c_str());
  const Imath::Box2i dw = file.header().dataWindow();
  w = dw.max.x - dw.min.x + 1;
  h = dw.max.y - dw.min.y + 1;
  if (w <= 0 || h <= 0 || static_cast<long long>(w) * h > (1ll << 28)) return true;  // the caller refuses it
  const Imf::ChannelList& channels = file.header().channels();
  const bool colour = channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
  if (!colour && !channels.findChannel("Y")) return false;
  rgb.assign(size_t(w) * size_t(h) * 3, 0.f);
  const size_t xs = 3 * sizeof(float), ys = xs * size_t(w);
  char* base = reinterpret_cast<char*>(rgb.data()) - (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * w) * ptrdiff_t(xs);
  if (colour) {
    Imf::FrameBuffer fb;
    for (int k = 0; k < 3; ++k)
      fb.insert(k == 0 ? "R" : k == 1 ? "G" : "B", Imf::Slice(Imf::FLOAT, base + k * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return true;
  }
  Imf::RgbaInputFile grey(path.c_str());
  Imf::Array2D<Imf::Rgba> pixels(h, w);
  grey.setFrameBuffer(&pixels[0][0] - dw.min.x - static_cast<long>(dw.min.y) * w, 1, static_cast<size_t>(w));
  grey.readPixels(dw.min.y, dw.max.y);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Imf::Rgba& p = pixels[y][x];
      float* c = &rgb[(size_t(y) * w + x) * 3];
      c[0] = float(p.r), c[1] = float(p.g), c[2] = float(p.b);
    }
  return true;
}

}  // namespace

Status load_sky_exr(const std::string& path, Sky& sky) {
  // A FIFO or a device would block the reader or feed it without end: asked before any open.
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    return Status::io(path, "the sky map is not a regular file");
  if (!std::ifstream(path, std::ios::binary).good()) return Status::io(path, "cannot open the sky map");
  int w = 0, h = 0;
  std::vector<float> rgb;
  try {
    if (!read_sky_pixels(path, w, h, rgb))
      return Status::invalid(path, "channels", "no R, G and B (or Y) channels: the sky map holds no colour");
  } catch (const std::exception& e) {
    return Status::invalid(path, "sky map", e.what());
  }
  if (w <= 0 || h <= 0 || static_cast<long long>(w) * h > (1ll << 28))
    return Status::invalid(path, "dataWindow", "unsupported sky map size");
  sky.width = w;
  sky.height = h;
  sky.replaced_values = 0;
  for (float& c : rgb)
    if (!(std::isfinite(c) && c >= 0.f)) {
      sky.replaced_values += !(c == 0.f);  // -0 is 0
      c = 0.f;
    }
  sky.rgb = std::move(rgb);
  build_sky_sampling(sky);
  return Status::ok();
}

}  // namespace gibake
