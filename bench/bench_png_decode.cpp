// PNG decoding at import: the fast path (io/gltf/png_decode.h, libdeflate) against stb_image on
// every PNG of a folder, one thread, both in this process, alternating, best of N rounds.
//   build/bench/bench_png_decode [folder (default: Sponza's)] [rounds (default 3)]
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/gltf/png_decode.h"
#include "io/gltf/texture_decode.h"
#include "io/timer.h"

namespace {
using Bytes = std::vector<unsigned char>;

struct Image {
  std::string name;
  Bytes png;
  gibake::gltf::ImageHeader header;
};

std::vector<Image> load_pngs(const std::filesystem::path& dir) {
  std::vector<Image> out;
  gibake::ImportLimits limits;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".png") continue;
    std::ifstream f(e.path(), std::ios::binary);
    Image im{
        e.path().filename().string(), Bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>()), {}};
    gibake::gltf::ImageBudget budget;
    budget.limits = &limits;
    std::string warning;
    if (gibake::gltf::check_image_header(im.png.data(), im.png.size(), "", "", budget, im.header, warning).is_ok() &&
        im.header.width > 0)
      out.push_back(std::move(im));
  }
  return out;
}

// A decoder as texture_decode.h declares them.
using Decoder = bool (*)(const unsigned char*, size_t, const gibake::gltf::ImageHeader&, std::vector<uint8_t>&);

// Seconds to decode every image with `decode`; `pixels` counts the megapixels decoded.
double time_all(const std::vector<Image>& images, Decoder decode, double& pixels, int& ok) {
  std::vector<uint8_t> rgba;
  pixels = 0.0;
  ok = 0;
  const gibake::Stopwatch timer;
  for (const Image& im : images) {
    if (decode(im.png.data(), im.png.size(), im.header, rgba)) ++ok;
    pixels += double(im.header.width) * im.header.height / 1e6;
  }
  return timer.seconds();
}
}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : std::string(GIBAKE_ASSETS_DIR) + "/sponza";
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  const std::vector<Image> images = load_pngs(dir);
  size_t bytes = 0, fast_taken = 0;
  for (const Image& im : images) {
    bytes += im.png.size();
    std::vector<uint8_t> rgba;
    fast_taken += gibake::gltf::decode_png_fast(im.png.data(), im.png.size(), im.header.width, im.header.height, rgba);
  }
  std::printf("%zu PNGs, %.1f MB, %zu through the fast path\n", images.size(), bytes / 1e6, fast_taken);
  double best_fast = 1e30, best_stb = 1e30, mp = 0.0;
  int ok_fast = 0, ok_stb = 0;
  for (int r = 0; r < rounds; ++r) {
    best_stb = std::min(best_stb, time_all(images, gibake::gltf::decode_rgba8_stb, mp, ok_stb));
    best_fast = std::min(best_fast, time_all(images, gibake::gltf::decode_rgba8, mp, ok_fast));
  }
  std::printf("stb_image:            %.3f s  (%.1f Mpixel/s, %d decoded)\n", best_stb, mp / best_stb, ok_stb);
  std::printf("decode_rgba8 (fast):  %.3f s  (%.1f Mpixel/s, %d decoded)\n", best_fast, mp / best_fast, ok_fast);
  std::printf("speed-up: %.2fx (best of %d rounds, one thread)\n", best_stb / best_fast, rounds);
  return 0;
}
