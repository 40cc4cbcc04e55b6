// What the importer reads leniently it says it ignored, with the place in the
// file; a required property of the wrong type and a non-GLB named .glb are named as what they are.
// The files are assimp's wrongTypes test models (shared assets, malformed/wrongTypes).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tests/support/cli_run.h"
#include "tests/support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace gibake::test;  // run_gibake_cli, shell_quote, split_lines, read_text_file

const std::string kWrong = std::string(GIBAKE_ASSETS_DIR) + "/malformed/wrongTypes/";

CliResult inspect(const std::string& path) {
  return run_gibake_cli("inspect " + shell_quote(path) + " --leak-audit off --format json");
}

// Read with exit 0 and exactly one warning naming `where` and what it expected.
void expect_one_ignored(const std::string& file, const std::string& where, const std::string& expected) {
  const CliResult r = inspect(kWrong + file);
  EXPECT_EQ(r.exit_code, 0) << file << ": " << r.err;
  const std::vector<std::string> lines = split_lines(r.err);
  ASSERT_EQ(lines.size(), 1u) << file << ": " << r.err;
  EXPECT_EQ(lines[0].rfind("gibake: warning: ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find(file + ": " + where + ": expected " + expected + ", got "), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("; ignored"), std::string::npos) << lines[0];
}

TEST(LenientParseCli, WrongTypesAreNamedWhereTheyAre) {
  expect_one_ignored("badUint.gltf", "materials[0].pbrMetallicRoughness.baseColorTexture.index",
                     "a non-negative integer");
  expect_one_ignored("badNumber.gltf", "materials[0].normalTexture.scale", "a number");
  expect_one_ignored("badObject.gltf", "materials[0].pbrMetallicRoughness", "an object");
  expect_one_ignored("badString.gltf", "scenes[0].name", "a string");
  expect_one_ignored("badExtension.gltf",
                     "materials[0].pbrMetallicRoughness.baseColorTexture.extensions.KHR_texture_transform",
                     "an object");
}

TEST(LenientParseCli, RequiredPropertyOfTheWrongTypeIsTheError) {
  const CliResult r = inspect(kWrong + "badArray.gltf");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  const std::vector<std::string> lines = split_lines(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_NE(lines[0].find("badArray.gltf: meshes[0].primitives: expected an array"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[0].find("no triangles"), std::string::npos) << lines[0];
}

TEST(LenientParseCli, NonGlbNamedGlbSaysBadMagic) {
  const fs::path png = gibake::test::process_tmp() / "lenient.glb";
  fs::copy_file(kWrong + "CesiumLogoFlat.png", png, fs::copy_options::overwrite_existing);
  const CliResult r = inspect(png.string());
  fs::remove(png);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("GLB header: not a GLB: bad magic"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("PNG"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("JSON"), std::string::npos) << r.err;
}

// The fuzz seeds (tests/fuzz/corpus/import: broken GLB framing, Draco, PNG/JPEG in GLBs, wrong
// types) through the real importer: each is read or refused with the documented exit code and one
// error line, never a crash.
TEST(LenientParseCli, FuzzSeedsAreReadOrRefusedCleanly) {
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(std::string(GIBAKE_SOURCE_DIR) + "/tests/fuzz/corpus/import")) {
    const CliResult r = inspect(entry.path().string());
    ++files;
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 2 || r.exit_code == 3) << entry.path() << ": " << r.exit_code;
    if (r.exit_code != 0) {
      const std::vector<std::string> lines = split_lines(r.err);
      ASSERT_FALSE(lines.empty()) << entry.path();
      EXPECT_EQ(lines.back().rfind("gibake: error: ", 0), 0u) << entry.path() << ": " << r.err;
    }
  }
  EXPECT_GE(files, 40u);
}

// Found by fuzz_import: a JPEG whose DHT code counts sum past 256 made stb_image write past its
// Huffman arrays. The pre-check refuses the image before stb reads it: one warning naming it, and
// the file (whose only mesh has no triangles) is refused as before, exit 3.
TEST(LenientParseCli, JpegWithOverlongHuffmanTableIsRefusedBeforeStb) {
  const CliResult r =
      inspect(std::string(GIBAKE_SOURCE_DIR) + "/tests/fuzz/corpus/import/regression_jpeg_dht_overflow.glb");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("images[1]: unsupported or corrupt image (JPEG marker segment runs past the file or has a "
                       "malformed Huffman table)"),
            std::string::npos)
      << r.err;
}

}  // namespace
