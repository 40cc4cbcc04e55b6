// The fast PNG path (io/gltf/png_decode.h) against stb_image, the decoder it stands in for: every
// image it accepts must give stb's pixels exactly, and whatever it declines must still decode
// through decode_rgba8 as stb decodes it.
#include "io/gltf/png_decode.h"

#include <gtest/gtest.h>
#include <libdeflate.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "import_testutil.h"
#include "io/gltf/texture_decode.h"

namespace gibake::gltf {
namespace {

using Bytes = std::vector<unsigned char>;

void put32(Bytes& b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<unsigned char>(v >> s));
}

void put_chunk(Bytes& png, const char* type, const Bytes& data) {
  put32(png, uint32_t(data.size()));
  const size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put32(png, libdeflate_crc32(0, png.data() + start, png.size() - start));
}

struct PngSpec {
  uint32_t width = 1, height = 1;
  int color_type = 6, depth = 8, interlace = 0;
  int channels = 4;
  uint32_t palette_entries = 0;
  uint32_t trns_entries = 0;  // palette alphas (colour type 3), or 1 colour key (0, 2)
  int idat_chunks = 1;
  bool break_adler = false;
  uint32_t index_limit = 0;  // palette indices drawn below this (default: the palette's size)
};

int paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
}

// Random pixels, each row filtered with a random filter (all five occur), deflated by libdeflate.
Bytes make_png(const PngSpec& s, std::mt19937& rng) {
  const size_t bpp = size_t(s.channels) * size_t(s.depth) / 8, stride = s.width * bpp;
  std::vector<Bytes> rows(s.height, Bytes(stride));
  for (Bytes& r : rows)
    for (unsigned char& v : r) {
      const uint32_t limit = s.index_limit ? s.index_limit : s.palette_entries;
      v = static_cast<unsigned char>(limit ? rng() % limit : rng());
    }
  Bytes raw;
  for (uint32_t y = 0; y < s.height; ++y) {
    const int f = int(rng() % 5);
    raw.push_back(static_cast<unsigned char>(f));
    for (size_t i = 0; i < stride; ++i) {
      const int a = i >= bpp ? rows[y][i - bpp] : 0, b = y ? rows[y - 1][i] : 0;
      const int c = (i >= bpp && y) ? rows[y - 1][i - bpp] : 0;
      const int pred[5] = {0, a, b, (a + b) >> 1, paeth(a, b, c)};
      raw.push_back(static_cast<unsigned char>(rows[y][i] - pred[f]));
    }
  }
  libdeflate_compressor* comp = libdeflate_alloc_compressor(int(rng() % 10));
  Bytes z(libdeflate_zlib_compress_bound(comp, raw.size()));
  z.resize(libdeflate_zlib_compress(comp, raw.data(), raw.size(), z.data(), z.size()));
  libdeflate_free_compressor(comp);
  if (s.break_adler) z.back() ^= 1;

  Bytes png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  Bytes ihdr;
  put32(ihdr, s.width);
  put32(ihdr, s.height);
  for (int v : {s.depth, s.color_type, 0, 0, s.interlace}) ihdr.push_back(static_cast<unsigned char>(v));
  put_chunk(png, "IHDR", ihdr);
  put_chunk(png, "tEXt", Bytes{'a', 0, 'b'});  // an ancillary chunk both decoders skip
  if (s.palette_entries) {
    Bytes pal(s.palette_entries * 3);
    for (unsigned char& v : pal) v = static_cast<unsigned char>(rng());
    put_chunk(png, "PLTE", pal);
  }
  if (s.trns_entries) {
    Bytes t(s.color_type == 3 ? s.trns_entries : size_t(s.channels) * 2);
    for (unsigned char& v : t) v = static_cast<unsigned char>(rng());
    put_chunk(png, "tRNS", t);
  }
  const size_t per = (z.size() + size_t(s.idat_chunks) - 1) / size_t(s.idat_chunks);
  for (size_t o = 0; o < z.size(); o += per)
    put_chunk(png, "IDAT", Bytes(z.begin() + long(o), z.begin() + long(std::min(z.size(), o + per))));
  put_chunk(png, "IEND", {});
  return png;
}

ImageHeader header_of(const PngSpec& s) { return ImageHeader{int(s.width), int(s.height)}; }

// decode_rgba8 (fast path first) gives stb's pixels; returns whether the fast path took the image.
bool expect_stb_pixels(const Bytes& png, const ImageHeader& h, const std::string& what) {
  std::vector<uint8_t> fast, stb, via;
  const bool took = decode_png_fast(png.data(), png.size(), h.width, h.height, fast);
  const bool stb_ok = decode_rgba8_stb(png.data(), png.size(), h, stb);
  EXPECT_EQ(decode_rgba8(png.data(), png.size(), h, via), stb_ok) << what;
  EXPECT_TRUE(via == stb) << what;
  if (took) {
    EXPECT_TRUE(stb_ok) << what << ": the fast path accepted an image stb refuses";
    EXPECT_TRUE(fast == stb) << what << ": the fast path's pixels differ from stb's";
  }
  return took;
}

TEST(PngDecode, EveryColourTypeAndFilterMatchesStb) {
  std::mt19937 rng(7);
  const uint32_t sizes[][2] = {{1, 1}, {7, 5}, {64, 33}, {3, 200}};
  struct Kind {
    int type, channels;
    uint32_t palette, trns;
  };
  const Kind kinds[] = {{0, 1, 0, 0},   {2, 3, 0, 0},  {4, 2, 0, 0},    {6, 4, 0, 0},
                        {3, 1, 256, 0}, {3, 1, 16, 0}, {3, 1, 200, 130}};
  int taken = 0, total = 0;
  for (const Kind& k : kinds)
    for (const auto& wh : sizes)
      for (int chunks : {1, 3}) {
        PngSpec s;
        s.width = wh[0], s.height = wh[1], s.color_type = k.type, s.channels = k.channels;
        s.palette_entries = k.palette, s.trns_entries = k.trns, s.idat_chunks = chunks;
        const std::string what = "type " + std::to_string(k.type) + " " + std::to_string(s.width) + "x" +
                                 std::to_string(s.height) + " idat " + std::to_string(chunks);
        taken += expect_stb_pixels(make_png(s, rng), header_of(s), what);
        ++total;
      }
  EXPECT_EQ(taken, total) << "every 8-bit non-interlaced image is the fast path's";
}

TEST(PngDecode, LeavesOtherImagesToStb) {
  std::mt19937 rng(11);
  PngSpec sixteen;
  sixteen.width = 9, sixteen.height = 4, sixteen.depth = 16, sixteen.color_type = 2, sixteen.channels = 3;
  PngSpec key;  // a colour key on RGB: stb's rule, not ours
  key.width = 5, key.height = 5, key.color_type = 2, key.channels = 3, key.trns_entries = 1;
  PngSpec adler;  // a bad checksum: libdeflate refuses, stb decides
  adler.width = 8, adler.height = 8, adler.break_adler = true;
  for (const PngSpec* s : {&sixteen, &key, &adler})
    EXPECT_FALSE(expect_stb_pixels(make_png(*s, rng), header_of(*s), "declined"));
  std::vector<uint8_t> out;
  const Bytes png = make_png(adler, rng);
  EXPECT_FALSE(decode_png_fast(png.data(), png.size(), 9, 8, out)) << "other dimensions than the header's";
}

TEST(PngDecode, TruncatedAndCorruptFilesNeverGoWrong) {
  std::mt19937 rng(3);
  PngSpec s;
  s.width = 13, s.height = 9, s.color_type = 3, s.channels = 1, s.palette_entries = 12, s.trns_entries = 5;
  s.idat_chunks = 2;
  const Bytes png = make_png(s, rng);
  for (size_t n = 0; n < png.size(); ++n)
    expect_stb_pixels(Bytes(png.begin(), png.begin() + long(n)), header_of(s), "cut at " + std::to_string(n));
  for (int i = 0; i < 2000; ++i) {
    Bytes bad = png;
    bad[rng() % bad.size()] ^= static_cast<unsigned char>(1u << (rng() % 8));
    expect_stb_pixels(bad, header_of(s), "flip " + std::to_string(i));
  }
}

// stb reads palette entries past the PLTE chunk from an uninitialised array; both routes must give
// opaque black there instead, on the fast path and through stb (a bad Adler-32 sends the file there).
TEST(PngDecode, IndexPastThePaletteIsOpaqueBlackOnBothRoutes) {
  std::mt19937 rng(5);
  PngSpec s;
  s.width = 16, s.height = 16, s.color_type = 3, s.channels = 1, s.palette_entries = 4, s.trns_entries = 3;
  s.index_limit = 256;
  for (bool broken : {false, true}) {
    s.break_adler = broken;
    const Bytes png = make_png(s, rng);
    const uint32_t ihdr_to_plte = 8 + 25 + 15;  // the signature, IHDR, the tEXt chunk
    ASSERT_EQ(std::string(png.begin() + ihdr_to_plte + 4, png.begin() + ihdr_to_plte + 8), "PLTE");
    const unsigned char* plte = png.data() + ihdr_to_plte + 8;
    const unsigned char* trns = plte + 4 * 3 + 12;
    std::vector<uint8_t> out;
    ASSERT_TRUE(decode_rgba8(png.data(), png.size(), header_of(s), out));
    EXPECT_EQ(decode_png_fast(png.data(), png.size(), 16, 16, out), !broken);
    ASSERT_TRUE(decode_rgba8(png.data(), png.size(), header_of(s), out));
    // The raw indices are not at hand here, so every pixel must be one of the four entries (alpha
    // from tRNS for the first three) or opaque black, and black must occur (252 of 256 draws are past).
    int black = 0;
    for (size_t p = 0; p < out.size(); p += 4) {
      bool known = false;
      for (int e = 0; e < 4; ++e)
        known |= out[p] == plte[e * 3] && out[p + 1] == plte[e * 3 + 1] && out[p + 2] == plte[e * 3 + 2] &&
                 out[p + 3] == (e < 3 ? trns[e] : 255);
      const bool is_black = out[p] == 0 && out[p + 1] == 0 && out[p + 2] == 0 && out[p + 3] == 255;
      black += is_black;
      EXPECT_TRUE(known || is_black) << "pixel " << p / 4 << (broken ? " through stb" : " on the fast path");
    }
    EXPECT_GT(black, 200);
    expect_stb_pixels(png, header_of(s), broken ? "past the palette, via stb" : "past the palette");
  }
}

TEST(PngDecode, TransparencyLongerThanThePaletteIsRefusedLikeStb) {
  std::mt19937 rng(9);
  PngSpec s;
  s.width = 4, s.height = 4, s.color_type = 3, s.channels = 1, s.palette_entries = 4, s.trns_entries = 5;
  const Bytes png = make_png(s, rng);
  std::vector<uint8_t> out;
  EXPECT_FALSE(decode_rgba8(png.data(), png.size(), header_of(s), out));
  std::vector<unsigned char> padded;
  EXPECT_EQ(pad_palette_for_stb(png.data(), png.size(), padded), PalettePad::refused);
}

TEST(PngDecode, SharedAssetsMatchStb) {
  namespace fs = std::filesystem;
  const fs::path root = test::assets_dir();
  if (!fs::exists(root)) GTEST_SKIP() << "no shared assets at " << root;
  int taken = 0, total = 0;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.path().extension() != ".png" || e.file_size() > (size_t(8) << 20)) continue;
    std::ifstream f(e.path(), std::ios::binary);
    const Bytes png((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    ImageBudget budget;
    ImportLimits limits;
    budget.limits = &limits;
    ImageHeader h;
    std::string warning;
    if (!check_image_header(png.data(), png.size(), "t", "t", budget, h, warning).is_ok() || h.width == 0) continue;
    taken += expect_stb_pixels(png, h, e.path().string());
    ++total;
  }
  std::printf("shared assets: %d of %d PNGs through the fast path\n", taken, total);
  EXPECT_GT(taken, 0);
}

}  // namespace
}  // namespace gibake::gltf

// Found by fuzz_import: a PNG whose IDAT declares far more bytes than the file holds made stb_image
// grow its buffer to 2 GiB before reading. Such a file is refused before stb sees it; a real PNG
// and anything that is not a PNG pass the check.
TEST(PngDecode, ChunkLongerThanTheFileIsRefusedBeforeStb) {
  const std::string logo = std::string(GIBAKE_ASSETS_DIR) + "/malformed/wrongTypes/CesiumLogoFlat.png";
  std::ifstream in(logo, std::ios::binary);
  std::vector<unsigned char> png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(png.size(), 33u);
  EXPECT_TRUE(gibake::gltf::png_chunks_fit(png.data(), png.size()));
  std::vector<unsigned char> lying = png;
  // The length of the chunk after the 8-byte signature and the 25-byte IHDR chunk: 1 GiB.
  const unsigned char gib[4] = {0x40, 0x00, 0x00, 0x00};
  std::copy(gib, gib + 4, lying.begin() + 33);
  EXPECT_FALSE(gibake::gltf::png_chunks_fit(lying.data(), lying.size()));
  gibake::gltf::ImageHeader header{1, 1};
  std::vector<uint8_t> rgba;
  EXPECT_FALSE(gibake::gltf::decode_rgba8(lying.data(), lying.size(), header, rgba));
  const unsigned char jpeg[4] = {0xff, 0xd8, 0xff, 0xe0};
  EXPECT_TRUE(gibake::gltf::png_chunks_fit(jpeg, sizeof jpeg));
}
