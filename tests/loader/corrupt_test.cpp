// Corrupted files: every case gives its documented loader error and `gibake verify` exit 3.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "io/bakefile/bake_file.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;
using loader::ErrorCode;

std::vector<uint8_t> valid_file(const std::string& metadata_json = "") {
  static const DdgiResult r = test::make_ddgi(3, 2, 2, 2, 9);
  BakeOutputs outputs;
  outputs.ddgi = &r;
  outputs.metadata_json = metadata_json;
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(build_bake_file(outputs, BakeFileOptions{}, bytes).is_ok());
  return bytes;
}

loader::Error load(const std::vector<uint8_t>& bytes) {
  loader::BakeFile file;
  return file.open_borrowed(bytes.data(), bytes.size());
}

class CorruptFiles : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::scratch_dir("corrupt"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  // Expects the loader error and `gibake verify` exit code 3 (JSON result "invalid").
  void expect_invalid(const std::vector<uint8_t>& bytes, ErrorCode code, const std::string& mention = "") {
    const loader::Error e = load(bytes);
    EXPECT_EQ(e.code, code) << e.message;
    if (!mention.empty()) {
      EXPECT_NE(e.message.find(mention), std::string::npos) << e.message;
    }
    const std::string path = dir_ + "/bad.bin";
    test::write_bytes(path, bytes);
    const test::RunResult run = test::run_gibake("verify " + path + " --format json");
    EXPECT_EQ(run.exit_code, 3) << run.out;
    EXPECT_NE(run.out.find("\"invalid\""), std::string::npos) << run.out;
  }
  std::string dir_;
};

TEST_F(CorruptFiles, FlippedByteInEachSectionNamesTheSection) {
  const std::vector<uint8_t> good = valid_file();
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(good.data(), good.size()));
  const std::vector<gibake_section_entry> sections = file.sections();
  ASSERT_GE(sections.size(), 8u);
  for (uint32_t i = 0; i < sections.size(); ++i) {
    std::vector<uint8_t> bad = good;
    bad[sections[i].offset + sections[i].size / 2] ^= 0x40;
    expect_invalid(bad, ErrorCode::SectionChecksum,
                   "section " + std::to_string(i) + " (" + loader::section_type_name(sections[i].type) + ")");
  }
}

TEST_F(CorruptFiles, HeaderAndTableBytes) {
  std::vector<uint8_t> bad = valid_file();
  bad[41] ^= 1;  // input hash
  expect_invalid(bad, ErrorCode::HeaderChecksum);
  bad = valid_file();
  bad[64 + 3] ^= 1;  // first table entry
  expect_invalid(bad, ErrorCode::TableChecksum);
}

TEST_F(CorruptFiles, Truncated) {
  std::vector<uint8_t> bad = valid_file();
  bad.resize(bad.size() - 100);
  expect_invalid(bad, ErrorCode::Truncated);
  bad.resize(40);
  expect_invalid(bad, ErrorCode::Truncated);
  expect_invalid({}, ErrorCode::Truncated);
}

TEST_F(CorruptFiles, WrongMagic) {
  std::vector<uint8_t> bad = valid_file();
  bad[0] = 'X';
  expect_invalid(bad, ErrorCode::BadMagic);
}

TEST_F(CorruptFiles, FutureMajorVersion) {
  std::vector<uint8_t> bad = valid_file();
  bad[8] = 2;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::UnsupportedVersion, "major version 2");
}

TEST_F(CorruptFiles, FutureMinorVersionAndUnknownSectionAreAccepted) {
  std::vector<uint8_t> ok = valid_file();
  ok[10] = 7;                           // minor 7
  test::table_entry(ok, 1)->type = 99;  // unknown type: skipped (but still checksummed)
  test::reseal(ok);
  loader::BakeFile file;
  // The SH section became "unknown", so the volume lacks SH: a MissingSection error, not a crash.
  EXPECT_EQ(file.open_borrowed(ok.data(), ok.size()).code, ErrorCode::MissingSection);
  ok = valid_file();
  ok[10] = 7;
  test::table_entry(ok, 2)->type = 99;  // offsets are optional
  test::reseal(ok);
  const loader::Error e = file.open_borrowed(ok.data(), ok.size());
  EXPECT_FALSE(e) << e.message;
  EXPECT_FALSE(file.ddgi_volumes()[0].has_offsets());
}

// The header's flags and an entry's flags and reserved words are 0 in every 1.x file: a set bit
// names a feature this reader cannot know to honour.
TEST_F(CorruptFiles, ReservedHeaderAndEntryFieldsAreRefused) {
  std::vector<uint8_t> bad = valid_file();
  const uint32_t flag = 0x80000001u;
  std::memcpy(bad.data() + offsetof(gibake_file_header, flags), &flag, sizeof flag);
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadHeader, "header flags");
  bad = valid_file();
  test::table_entry(bad, 1)->flags = 7;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadSectionTable, "reserved");
  bad = valid_file();
  test::table_entry(bad, 2)->reserved[0] = 0xdeadbeef;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadSectionTable, "reserved");
}

TEST_F(CorruptFiles, OverlappingSections) {
  std::vector<uint8_t> bad = valid_file();
  gibake_section_entry* a = test::table_entry(bad, 2);
  const gibake_section_entry* b = test::table_entry(bad, 1);
  a->offset = b->offset + 16;  // inside the SH section
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::SectionOverlap, "overlaps");
  bad = valid_file();
  test::table_entry(bad, 0)->offset = 64;  // on top of the table
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::SectionOverlap, "section table");
}

TEST_F(CorruptFiles, OutOfRangeSection) {
  std::vector<uint8_t> bad = valid_file();
  test::table_entry(bad, 1)->offset = bad.size() + 4096;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::SectionOutOfRange, "section 1 (ddgi_sh)");
  bad = valid_file();
  test::table_entry(bad, 1)->size = ~uint64_t(0) - 8;  // wraps around with the offset
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::SectionOutOfRange);
  bad = valid_file();
  gibake_file_header h;
  std::memcpy(&h, bad.data(), sizeof h);
  h.section_count = 1u << 30;
  std::memcpy(bad.data(), &h, sizeof h);
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadSectionTable);
}

TEST_F(CorruptFiles, MisalignedAndFormatMismatch) {
  std::vector<uint8_t> bad = valid_file();
  test::table_entry(bad, 1)->offset += 4;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::SectionMisaligned);
  bad = valid_file();
  test::table_entry(bad, 1)->format = GIBAKE_FORMAT_RGBA16F;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadElementFormat);
  bad = valid_file();
  test::table_entry(bad, 1)->count -= 3;  // size no longer count * 4
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadElementFormat);
}

TEST_F(CorruptFiles, InconsistentVolume) {
  std::vector<uint8_t> bad = valid_file();
  const gibake_section_entry* vol = test::table_entry(bad, 0);
  gibake_ddgi_volume d;
  std::memcpy(&d, bad.data() + vol->offset, sizeof d);
  d.counts[0] = 4;  // probe_count no longer the product
  std::memcpy(bad.data() + vol->offset, &d, sizeof d);
  test::table_entry(bad, 0)->checksum = loader::xxh64(&d, sizeof d, 0);
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadVolume, "probe_count");
}

// Every byte of a file is accounted for: padding is zero, nothing follows the last section's
// padded end, and there is no gap the layout does not explain (docs/FORMAT.md).
std::vector<std::pair<uint64_t, uint64_t>> padding_ranges(const std::vector<uint8_t>& bytes) {
  loader::BakeFile file;
  EXPECT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
  std::vector<std::pair<uint64_t, uint64_t>> used = {{0, 64}};
  gibake_file_header h;
  std::memcpy(&h, bytes.data(), sizeof h);
  used.push_back({h.section_table_offset, h.section_table_offset + h.section_count * sizeof(gibake_section_entry)});
  for (const gibake_section_entry& s : file.sections())
    if (s.size) used.push_back({s.offset, s.offset + s.size});
  std::sort(used.begin(), used.end());
  std::vector<std::pair<uint64_t, uint64_t>> gaps;
  for (size_t i = 0; i < used.size(); ++i) {
    const uint64_t next = i + 1 < used.size() ? used[i + 1].first : bytes.size();
    if (next > used[i].second) gaps.push_back({used[i].second, next});
  }
  return gaps;
}

TEST_F(CorruptFiles, EveryPaddingByteIsChecked) {
  // A metadata JSON whose length leaves padding after it (the file's last section).
  std::vector<uint8_t> good;
  for (std::string tool = "x"; tool.size() < 64; tool += "x") {  // at most 16 lengths are needed
    good = valid_file(R"({"tool":")" + tool + R"("})");
    const auto gaps = padding_ranges(good);
    if (!gaps.empty() && gaps.back().second == good.size()) break;
  }
  EXPECT_FALSE(load(good)) << "an untouched file passes";
  const auto gaps = padding_ranges(good);
  // Padding after a payload whose size is not a multiple of 16 (the 2-byte states section) and
  // after the metadata; the writer leaves none between the header, the table and the first section.
  ASSERT_GE(gaps.size(), 2u);
  EXPECT_EQ(gaps.back().second, good.size());
  size_t flipped = 0;
  for (const auto& [begin, end] : gaps) {
    for (uint64_t at = begin; at < end; ++at) {
      std::vector<uint8_t> bad = good;
      bad[at] = 0x5a;  // no checksum covers padding: only the layout check sees this
      const loader::Error e = load(bad);
      EXPECT_EQ(e.code, ErrorCode::BadPadding) << "offset " << at << ": " << e.message;
      EXPECT_NE(e.message.find("at offset " + std::to_string(at) + " "), std::string::npos) << e.message;
      ++flipped;
    }
    // One byte per class also through `gibake verify` (exit 3), the last padding byte of the gap.
    std::vector<uint8_t> bad = good;
    bad[end - 1] = 0x01;
    expect_invalid(bad, ErrorCode::BadPadding, "non-zero padding byte 0x01 at offset " + std::to_string(end - 1));
  }
  EXPECT_GT(flipped, 0u);
}

// After a test grew or shrank the file: the header's file_size made to agree, then resealed.
void set_file_size(std::vector<uint8_t>& bytes) {
  gibake_file_header h;
  std::memcpy(&h, bytes.data(), sizeof h);
  h.file_size = bytes.size();
  std::memcpy(bytes.data(), &h, sizeof h);
  test::reseal(bytes);
}

TEST_F(CorruptFiles, BytesAfterTheLastSectionAreRefused) {
  const std::vector<uint8_t> good = valid_file();
  for (size_t extra : {1u, 15u, 16u, 64u}) {
    std::vector<uint8_t> bad = good;
    bad.resize(good.size() + extra, 0);  // zeros, and the header's file_size agrees
    set_file_size(bad);
    expect_invalid(bad, ErrorCode::BadPadding,
                   std::to_string(extra) + " bytes at offset " + std::to_string(good.size()) + " follow the padded end");
  }
  // A trailing byte the header does not announce is the older size check (BadHeader).
  std::vector<uint8_t> bad = good;
  bad.push_back(0);
  expect_invalid(bad, ErrorCode::BadHeader, "longer than the recorded");
}

TEST_F(CorruptFiles, GapsTheLayoutDoesNotExplainAreRefused) {
  const std::vector<uint8_t> good = valid_file();
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(good.data(), good.size()));
  const uint64_t first = file.sections()[0].offset;  // right after the table
  // 16 zero bytes between the section table and the first section, every offset moved past them.
  std::vector<uint8_t> bad(good.begin(), good.begin() + long(first));
  bad.insert(bad.end(), 16, 0);
  bad.insert(bad.end(), good.begin() + long(first), good.end());
  for (size_t i = 0; i < file.sections().size(); ++i) test::table_entry(bad, i)->offset += 16;
  set_file_size(bad);
  expect_invalid(bad, ErrorCode::BadPadding,
                 "bytes [" + std::to_string(first) + ", " + std::to_string(first + 16) +
                     ") between the section table and section 0 (ddgi_volume) are not explained by the layout");
  // A gap between two sections: the last section (metadata) moved 16 bytes on.
  bad = good;
  const size_t last = file.sections().size() - 1;
  const gibake_section_entry meta = file.sections()[last];
  bad.insert(bad.begin() + long(meta.offset), 16, 0);
  test::table_entry(bad, last)->offset += 16;
  set_file_size(bad);
  expect_invalid(bad, ErrorCode::BadPadding, "section " + std::to_string(last) + " (metadata) should start at offset " +
                                                 std::to_string(meta.offset));
  // The format's freedoms still pass: sections listed in another order than they lie in.
  std::vector<uint8_t> swapped = good;
  std::swap(*test::table_entry(swapped, 2), *test::table_entry(swapped, 3));
  test::reseal(swapped);
  loader::BakeFile ok;
  const loader::Error e = ok.open_borrowed(swapped.data(), swapped.size());
  EXPECT_FALSE(e) << e.message;
}

TEST_F(CorruptFiles, ChecksumsCanBeSkipped) {
  std::vector<uint8_t> bad = valid_file();
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(bad.data(), bad.size()));
  bad[file.sections().back().offset + 1] ^= 0x10;  // inside the metadata payload
  EXPECT_TRUE(file.open_borrowed(bad.data(), bad.size()));
  EXPECT_FALSE(file.open_borrowed(bad.data(), bad.size(), loader::LoadOptions{false}));
}

}  // namespace
