#include "bake/scene/sky.h"

#include <OpenEXR/ImfArray.h>
#include <OpenEXR/ImfRgbaFile.h>

#include <cmath>
#include <exception>
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

bool Sky::is_black() const {
  if (scale <= 0.f) return true;
  if (rgb.empty()) return constant.x <= 0.f && constant.y <= 0.f && constant.z <= 0.f;
  for (float c : rgb)
    if (c > 0.f) return false;
  return true;
}

Status load_sky_exr(const std::string& path, Sky& sky) {
  if (!std::ifstream(path, std::ios::binary).good()) return Status::io(path, "cannot open the sky map");
  try {
    Imf::RgbaInputFile file(path.c_str());
    const Imath::Box2i dw = file.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || static_cast<long long>(w) * h > (1ll << 28))
      return Status::invalid(path, "dataWindow", "unsupported sky map size");
    Imf::Array2D<Imf::Rgba> pixels(h, w);
    file.setFrameBuffer(&pixels[0][0] - dw.min.x - static_cast<long>(dw.min.y) * w, 1, static_cast<size_t>(w));
    file.readPixels(dw.min.y, dw.max.y);
    sky.width = w;
    sky.height = h;
    sky.rgb.resize(size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Imf::Rgba& p = pixels[y][x];
        float c[3] = {float(p.r), float(p.g), float(p.b)};
        for (int k = 0; k < 3; ++k) sky.rgb[(size_t(y) * w + x) * 3 + k] = std::isfinite(c[k]) && c[k] > 0.f ? c[k] : 0.f;
      }
  } catch (const std::exception& e) {
    return Status::invalid(path, "sky map", e.what());
  }
  return Status::ok();
}

}  // namespace gibake
