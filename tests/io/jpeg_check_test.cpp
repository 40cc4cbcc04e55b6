// The JPEG pre-check (io/gltf/jpeg_check.h): real JPEGs pass, and the malformed marker segments
// that would make stb_image write past its Huffman arrays are refused before stb reads them.
#include "io/gltf/jpeg_check.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/gltf/texture_decode.h"
#include "io/gltf/import.h"

namespace gibake::gltf {
namespace {

using Bytes = std::vector<unsigned char>;

Bytes read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Offset of the first marker segment `m` (its 0xFF byte) before the first scan, or 0.
size_t find_segment(const Bytes& jpg, unsigned char m) {
  for (size_t p = 2; p + 4 <= jpg.size();) {
    if (jpg[p] != 0xFF) return 0;
    if (jpg[p + 1] == m) return p;
    if (jpg[p + 1] == 0xDA) return 0;
    p += 2 + (size_t(jpg[p + 2]) << 8 | jpg[p + 3]);
  }
  return 0;
}

const std::string kJpeg = std::string(GIBAKE_ASSETS_DIR) + "/lights-punctual-lamp/material0_emissive.jpeg";

bool header_warns(const Bytes& jpg) {
  ImportLimits limits;
  ImageBudget budget;
  budget.limits = &limits;
  ImageHeader header;
  std::string warning;
  EXPECT_TRUE(check_image_header(jpg.data(), jpg.size(), "f.glb", "images[0]", budget, header, warning).is_ok());
  return !warning.empty() && header.width == 0;
}

TEST(JpegCheck, RealJpegsPass) {
  size_t checked = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(GIBAKE_ASSETS_DIR)) {
    const std::string ext = e.path().extension().string();
    if (ext != ".jpg" && ext != ".jpeg" && ext != ".JPG") continue;
    const Bytes jpg = read_all(e.path().string());
    EXPECT_TRUE(jpeg_segments_fit(jpg.data(), jpg.size())) << e.path();
    ++checked;
  }
  std::printf("shared assets: %zu JPEGs checked\n", checked);
  EXPECT_GT(checked, 3u);
  const Bytes png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_TRUE(jpeg_segments_fit(png.data(), png.size()));
}

// Found by fuzz_import: a DHT whose 16 code counts sum past 256 made stb_image index its 257-entry
// size table out of bounds (UBSan, stb_image.h stbi__build_huffman), in stbi_info already.
TEST(JpegCheck, HuffmanCountsOver256AreRefusedBeforeStb) {
  Bytes jpg = read_all(kJpeg);
  ASSERT_GT(jpg.size(), 1000u);
  ASSERT_FALSE(header_warns(jpg));
  const size_t dht = find_segment(jpg, 0xC4);
  ASSERT_GT(dht, 0u);
  Bytes bad = jpg;
  bad[dht + 5] = 200;  // counts of 1- and 2-bit codes: 200 + 200 > 256
  bad[dht + 6] = 200;
  EXPECT_FALSE(jpeg_segments_fit(bad.data(), bad.size()));
  EXPECT_TRUE(header_warns(bad));
  ImageHeader header{16, 16};
  std::vector<uint8_t> rgba;
  EXPECT_FALSE(decode_rgba8(bad.data(), bad.size(), header, rgba));
}

TEST(JpegCheck, BadTableIdsAndCountsPastTheSegmentAreRefused) {
  const Bytes jpg = read_all(kJpeg);
  const size_t dht = find_segment(jpg, 0xC4);
  ASSERT_GT(dht, 0u);
  Bytes bad_class = jpg;
  bad_class[dht + 4] = 0x20 | (jpg[dht + 4] & 15);  // class 2
  EXPECT_FALSE(jpeg_segments_fit(bad_class.data(), bad_class.size()));
  Bytes bad_id = jpg;
  bad_id[dht + 4] = (jpg[dht + 4] & 0xF0) | 4;  // table 4
  EXPECT_FALSE(jpeg_segments_fit(bad_id.data(), bad_id.size()));
  Bytes short_segment = jpg;  // the segment length says 17 + 1 bytes; the counts ask for more
  short_segment[dht + 2] = 0;
  short_segment[dht + 3] = 2 + 17 + 1;
  EXPECT_FALSE(jpeg_segments_fit(short_segment.data(), short_segment.size()));
}

TEST(JpegCheck, SegmentLongerThanTheFileIsRefused) {
  const Bytes jpg = read_all(kJpeg);
  const size_t dqt = find_segment(jpg, 0xDB);
  ASSERT_GT(dqt, 0u);
  const Bytes cut(jpg.begin(), jpg.begin() + long(dqt) + 10);  // inside the DQT segment
  EXPECT_FALSE(jpeg_segments_fit(cut.data(), cut.size()));
  Bytes tiny = {0xFF, 0xD8, 0xFF, 0xE0, 0x00};
  EXPECT_FALSE(jpeg_segments_fit(tiny.data(), tiny.size()));
  tiny = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x01};  // a length below its own two bytes
  EXPECT_FALSE(jpeg_segments_fit(tiny.data(), tiny.size()));
}

// DHT segments also come between the scans of a progressive JPEG; the walk skips entropy-coded
// data (stuffed 0xFF00 and restart markers) to reach them.
TEST(JpegCheck, TablesAfterTheFirstScanAreChecked) {
  Bytes jpg = {0xFF, 0xD8, 0xFF, 0xDA, 0x00, 0x02, 0x12, 0xFF, 0x00, 0x34, 0xFF, 0xD0, 0x56};
  const size_t tail = jpg.size();
  jpg.insert(jpg.end(), {0xFF, 0xC4, 0x00, 2 + 17, 0x10});
  jpg.insert(jpg.end(), 16, 0);  // no codes: sound
  jpg.insert(jpg.end(), {0xFF, 0xD9});
  EXPECT_TRUE(jpeg_segments_fit(jpg.data(), jpg.size()));
  jpg[tail + 5] = 255;  // 255 one-bit codes, in a segment that holds none
  jpg[tail + 6] = 255;
  EXPECT_FALSE(jpeg_segments_fit(jpg.data(), jpg.size()));
}

}  // namespace
}  // namespace gibake::gltf
