// Format 1.2 LPV sections: write -> load round trip, sample_lpv against the bake kernel at cell
// centres (C++ and C API), corrupt LPV sections refused with their documented errors, info and
// verify on LPV files, a real `gibake --lpv` bake.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "gibake/loader.h"
#include "io/bakefile/bake_file.h"
#include "kernels/lpv.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;
using loader::ErrorCode;

std::vector<uint8_t> build(const LpvResult& lpv, FloatPrecision sh = FloatPrecision::Full, bool with_ddgi = true) {
  static const DdgiResult ddgi = test::make_ddgi(2, 2, 1, 1, 3, false);
  BakeOutputs outputs;
  if (with_ddgi) outputs.ddgi = &ddgi;
  outputs.lpv = &lpv;
  BakeFileOptions options;
  options.sh = sh;
  std::vector<uint8_t> bytes;
  const Status s = build_bake_file(outputs, options, bytes);
  EXPECT_TRUE(s.is_ok()) << s.message();
  return bytes;
}

kernels::LpvCell cell_of(const LpvCascade& c, size_t i) {
  kernels::LpvCell cell;
  std::memcpy(cell.sh, &c.sh[i * 12], sizeof cell.sh);
  return cell;
}

const loader::Vec3 kNormals[] = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {0, 0, -1}, {0.577350f, 0.577350f, -0.577350f}};

TEST(LpvFormat, RoundTripAndSamplerMatchesKernelAtCellCentres) {
  const LpvResult lpv = test::make_lpv(4, 3, 5, 2, 17);
  const std::vector<uint8_t> bytes = build(lpv);
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
  EXPECT_EQ(file.header().version_minor, 2);
  ASSERT_EQ(file.lpv_cascades().size(), 2u);
  ASSERT_EQ(file.ddgi_volumes().size(), 1u);
  for (size_t k = 0; k < 2; ++k) {
    const loader::LpvCascade& c = file.lpv_cascades()[k];
    const LpvCascade& ref = lpv.cascades[k];
    EXPECT_EQ(c.desc().cascade_index, k);
    EXPECT_EQ(c.desc().cascade_count, 2u);
    EXPECT_EQ(c.desc().cell_count, ref.cell_count());
    EXPECT_EQ(c.desc().cell_size, ref.cell_size);
    EXPECT_EQ(c.desc().units, uint32_t(GIBAKE_UNITS_CANDELA));
    EXPECT_EQ((c.desc().flags & GIBAKE_LPV_FLAG_OCCLUSION) != 0, ref.occlusion);
    for (size_t i = 0; i < ref.cell_count(); ++i)
      for (uint32_t v = 0; v < 12; ++v) ASSERT_EQ(c.sh(uint32_t(i), v / 4, v % 4), ref.sh[i * 12 + v]);
  }
  // Every cell centre of every cascade: the file's sampler (finest cascade containing the point)
  // equals the kernel's irradiance of that cascade's cell, to float rounding (1e-5 relative).
  gibake_file* cfile = nullptr;
  ASSERT_EQ(gibake_open_memory(bytes.data(), bytes.size(), 1, &cfile, nullptr, 0), 0);
  ASSERT_EQ(gibake_lpv_cascade_count(cfile), 2u);
  size_t checked = 0;
  for (size_t k = 0; k < 2; ++k) {
    const LpvCascade& ref = lpv.cascades[k];
    const loader::LpvCascade& c = file.lpv_cascades()[k];
    for (int z = 0; z < ref.dims[2]; ++z)
      for (int y = 0; y < ref.dims[1]; ++y)
        for (int x = 0; x < ref.dims[0]; ++x) {
          const loader::Vec3 p = c.cell_centre(x, y, z);
          if (k == 1 && file.lpv_cascades()[0].contains(p)) continue;  // the finer cascade answers there
          const size_t i = size_t(x) + size_t(ref.dims[0]) * (size_t(y) + size_t(ref.dims[1]) * size_t(z));
          for (const loader::Vec3& n : kNormals) {
            const kernels::float3 e = kernels::lpv_cell_irradiance(cell_of(ref, i), {n[0], n[1], n[2]}, ref.cell_size);
            const loader::Rgb got = file.sample_lpv(p, n);
            float cgot[3];
            ASSERT_EQ(gibake_sample_lpv(cfile, p.data(), n.data(), cgot), 0);
            const float want[3] = {e.x, e.y, e.z};
            for (int ch = 0; ch < 3; ++ch) {
              EXPECT_NEAR(got[size_t(ch)], want[ch], 1e-5f * std::max(1.f, want[ch])) << k << " " << i;
              EXPECT_EQ(cgot[ch], got[size_t(ch)]);
            }
            ++checked;
          }
        }
  }
  EXPECT_GT(checked, 4u * 3u * 5u * 5u);
  float sh[12];
  EXPECT_EQ(gibake_lpv_cell_sh(cfile, 1, 7, sh), 0);
  EXPECT_EQ(sh[5], lpv.cascades[1].sh[7 * 12 + 5]);
  EXPECT_NE(gibake_lpv_cell_sh(cfile, 2, 0, sh), 0);
  EXPECT_EQ(gibake_lpv_cascade_desc(cfile, 2), nullptr);
  gibake_close(cfile);
  // Outside every cascade: black.
  const loader::Rgb outside = file.sample_lpv({100.f, 0.f, 0.f}, {0.f, 1.f, 0.f});
  EXPECT_EQ(outside[0] + outside[1] + outside[2], 0.f);
}

TEST(LpvFormat, TrilinearBetweenCentresAndHalfPrecision) {
  LpvResult lpv = test::make_lpv(2, 1, 1, 1, 3);
  // Cell 0 isotropic 1 cd, cell 1 isotropic 3 cd (c0 = I / Y00): halfway the irradiance is that of 2 cd.
  std::fill(lpv.cascades[0].sh.begin(), lpv.cascades[0].sh.end(), 0.f);
  for (int ch = 0; ch < 3; ++ch) {
    lpv.cascades[0].sh[size_t(ch) * 4] = 1.f / 0.282095f;
    lpv.cascades[0].sh[12 + size_t(ch) * 4] = 3.f / 0.282095f;
  }
  for (FloatPrecision precision : {FloatPrecision::Full, FloatPrecision::Half}) {
    const std::vector<uint8_t> bytes = build(lpv, precision, false);
    loader::BakeFile file;
    ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
    EXPECT_EQ(file.lpv_cascades()[0].sh_format(),
              uint32_t(precision == FloatPrecision::Half ? GIBAKE_FORMAT_F16 : GIBAKE_FORMAT_F32));
    const float h = lpv.cascades[0].cell_size;
    // E of an isotropic intensity I for any normal: pi * I / h^2.
    const loader::Rgb mid = file.sample_lpv({0.f, 0.f, 0.f}, {0.f, 1.f, 0.f});
    EXPECT_NEAR(mid[0], 3.14159265f * 2.f / (h * h), 2e-3f * 3.14159265f * 2.f / (h * h));
    const loader::Rgb edge = file.sample_lpv({-0.49f * 2 * h, 0.f, 0.f}, {1.f, 0.f, 0.f});  // clamped to cell 0
    EXPECT_NEAR(edge[1], 3.14159265f / (h * h), 2e-3f * 3.14159265f / (h * h));
  }
}

class LpvCorrupt : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir("lpv_corrupt");
    good_ = build(test::make_lpv(3, 2, 2, 2, 9));
    loader::BakeFile file;
    ASSERT_FALSE(file.open_borrowed(good_.data(), good_.size()));
    for (uint32_t i = 0; i < file.sections().size(); ++i) {
      if (file.sections()[i].type == GIBAKE_SECTION_LPV_CASCADE && cascade_ < 0) cascade_ = int(i);
      if (file.sections()[i].type == GIBAKE_SECTION_LPV_SH && sh_ < 0) sh_ = int(i);
    }
    ASSERT_GE(cascade_, 0);
    ASSERT_EQ(sh_, cascade_ + 1);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Rewrites the first cascade's descriptor through `edit` with a fresh checksum.
  template <typename F>
  std::vector<uint8_t> with_desc(F&& edit) {
    std::vector<uint8_t> bad = good_;
    gibake_section_entry* e = test::table_entry(bad, size_t(cascade_));
    gibake_lpv_cascade d;
    std::memcpy(&d, bad.data() + e->offset, sizeof d);
    edit(d);
    std::memcpy(bad.data() + e->offset, &d, sizeof d);
    e->checksum = loader::xxh64(&d, sizeof d, 0);
    test::reseal(bad);
    return bad;
  }
  void expect_invalid(const std::vector<uint8_t>& bytes, ErrorCode code, const std::string& mention) {
    loader::BakeFile file;
    const loader::Error e = file.open_borrowed(bytes.data(), bytes.size());
    EXPECT_EQ(e.code, code) << e.message;
    EXPECT_NE(e.message.find(mention), std::string::npos) << e.message;
    const std::string path = dir_ + "/bad.bin";
    test::write_bytes(path, bytes);
    const test::RunResult run = test::run_gibake("verify " + path + " --format json");
    EXPECT_EQ(run.exit_code, 3) << run.out;
  }
  std::string dir_;
  std::vector<uint8_t> good_;
  int cascade_ = -1, sh_ = -1;
};

TEST_F(LpvCorrupt, DescriptorFieldsOutOfRange) {
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.dims[1] = 3; }), ErrorCode::BadVolume, "cell_count");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.dims[0] = -1; }), ErrorCode::BadVolume, "axis 0");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) {
                   d.dims[0] = d.dims[1] = d.dims[2] = 4096;
                   d.cell_count = 0;
                 }),
                 ErrorCode::BadVolume, "cell_count");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.cell_size = 0.f; }), ErrorCode::BadVolume, "cell_size");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.cell_size = NAN; }), ErrorCode::BadVolume, "cell_size");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.grid_min[2] = INFINITY; }), ErrorCode::BadVolume, "finite");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.grid_min[0] = d.cell_size = 3e38f; }), ErrorCode::BadVolume,
                 "finite");  // the far corner overflows
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.sh_coefficients = 9; }), ErrorCode::BadVolume, "L1");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.units = GIBAKE_UNITS_LUX; }), ErrorCode::BadVolume, "units");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.flags = 6; }), ErrorCode::BadVolume, "flag");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.cascade_index = 2; }), ErrorCode::BadVolume, "cascade_index");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.cascade_index = 1; }), ErrorCode::BadVolume, "repeated");
  expect_invalid(with_desc([](gibake_lpv_cascade& d) { d.cascade_count = 3; d.cascade_index = 2; }), ErrorCode::BadVolume,
                 "cascade_count");
}

TEST_F(LpvCorrupt, TableEntries) {
  std::vector<uint8_t> bad = good_;
  test::table_entry(bad, size_t(sh_))->group = uint32_t(sh_);  // group names itself, not a cascade
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadVolume, "not an lpv_cascade");
  bad = good_;
  test::table_entry(bad, size_t(sh_))->group = 0;  // the DDGI volume
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadVolume, "not an lpv_cascade");
  bad = good_;
  test::table_entry(bad, size_t(sh_))->group = 0xffffffffu;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadVolume, "group");
  bad = good_;
  test::table_entry(bad, size_t(sh_) + 2)->group = uint32_t(cascade_);  // both SH sections on cascade 0
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::DuplicateSection, "lpv_sh");
  bad = good_;
  test::table_entry(bad, size_t(sh_))->type = 99;  // unknown type: skipped, so the cascade has no SH
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::MissingSection, "no lpv_sh");
  bad = good_;
  test::table_entry(bad, size_t(sh_))->format = GIBAKE_FORMAT_RGBA32F;
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadElementFormat, "lpv_sh");
  bad = good_;
  gibake_section_entry* e = test::table_entry(bad, size_t(sh_));
  e->count -= 12;  // one cell short (size shrinks with it)
  e->size -= 48;
  e->checksum = loader::xxh64(bad.data() + e->offset, e->size, 0);
  test::reseal(bad);
  expect_invalid(bad, ErrorCode::BadVolume, "cascade needs");
  bad = good_;
  test::table_entry(bad, size_t(cascade_))->count = 2;
  test::table_entry(bad, size_t(cascade_))->size = 128;
  test::reseal(bad);
  loader::BakeFile file;
  EXPECT_NE(file.open_borrowed(bad.data(), bad.size()).code, ErrorCode::Ok);
}

TEST_F(LpvCorrupt, FlippedPayloadByteNamesTheSection) {
  std::vector<uint8_t> bad = good_;
  bad[test::table_entry(bad, size_t(sh_))->offset + 100] ^= 0x20;
  expect_invalid(bad, ErrorCode::SectionChecksum, "(lpv_sh)");
}

TEST_F(LpvCorrupt, InfoAndVerifyOnAValidFile) {
  const std::string path = dir_ + "/good.bin";
  test::write_bytes(path, good_);
  const test::RunResult info = test::run_gibake_stdout("info " + path + " --format json");
  ASSERT_EQ(info.exit_code, 0) << info.out;
  const nlohmann::json j = nlohmann::json::parse(info.out);
  ASSERT_EQ(j["lpv"].size(), 2u);
  EXPECT_EQ(j["lpv"][1]["dims"], nlohmann::json::array({3, 2, 2}));
  EXPECT_EQ(j["lpv"][0]["occlusion"], true);
  const test::RunResult text = test::run_gibake("info " + path);
  EXPECT_NE(text.out.find("lpv cascade 1: 3x2x2 cells"), std::string::npos) << text.out;
  const test::RunResult verify = test::run_gibake("verify " + path + " --against " + path);
  EXPECT_EQ(verify.exit_code, 0) << verify.out;
  EXPECT_NE(verify.out.find("pass  lpv[1].nonnegative"), std::string::npos) << verify.out;
  EXPECT_NE(verify.out.find("pass  against.lpv[0].irradiance"), std::string::npos) << verify.out;
  // A different LPV: --against reports the cell and exits 7.
  const std::string other = dir_ + "/other.bin";
  test::write_bytes(other, build(test::make_lpv(3, 2, 2, 2, 10)));
  const test::RunResult diff = test::run_gibake("verify " + path + " --against " + other);
  EXPECT_EQ(diff.exit_code, 7) << diff.out;
  EXPECT_NE(diff.out.find("fail  against.lpv[0].irradiance: cell"), std::string::npos) << diff.out;
  // NaN in a cell and a negative intensity: verify refuses (exit 3). The writer refuses NaN light,
  // so the NaN file is a written one edited, its checksums made to match.
  LpvResult nan = test::make_lpv(3, 2, 2, 1, 9);
  nan.cascades[0].sh[30] = NAN;
  BakeOutputs refused;
  refused.lpv = &nan;
  std::vector<uint8_t> none;
  EXPECT_FALSE(build_bake_file(refused, BakeFileOptions{}, none).is_ok());
  std::vector<uint8_t> edited = build(test::make_lpv(3, 2, 2, 1, 9));
  gibake_file_header header;
  std::memcpy(&header, edited.data(), sizeof header);
  bool found = false;
  for (size_t i = 0; i < header.section_count && !found; ++i) {
    gibake_section_entry* e = test::table_entry(edited, i);
    if (e->type != GIBAKE_SECTION_LPV_SH) continue;  // the first: cascade 0's
    ASSERT_EQ(e->format, uint32_t(GIBAKE_FORMAT_F32));
    const float value = NAN;
    std::memcpy(edited.data() + e->offset + 30 * sizeof(float), &value, sizeof value);
    e->checksum = loader::xxh64(edited.data() + e->offset, size_t(e->size), GIBAKE_HASH_SEED);
    found = true;
  }
  ASSERT_TRUE(found);
  test::reseal(edited);
  test::write_bytes(other, edited);
  EXPECT_EQ(test::run_gibake("verify " + other).exit_code, 3);
  LpvResult negative = test::make_lpv(3, 2, 2, 1, 9);
  negative.cascades[0].sh[13] = 10.f * negative.cascades[0].sh[12];  // |c1| > sqrt(3) c0
  test::write_bytes(other, build(negative));
  const test::RunResult neg = test::run_gibake("verify " + other);
  EXPECT_EQ(neg.exit_code, 3) << neg.out;
  EXPECT_NE(neg.out.find("fail  lpv[0].nonnegative: cell 1"), std::string::npos) << neg.out;
}

TEST(LpvCli, BakeWritesCascadesThatVerify) {
  const std::string dir = test::scratch_dir("lpv_cli");
  const std::string out = dir + "/cornell.gibake";
  const std::string scene = std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf";
  const test::RunResult bake = test::run_gibake(scene + " --ddgi --probe-counts 3,3,3 --rays 32 --bounces 1 --lpv "
                                                "--lpv-res 8 --lpv-cascades 2 --lpv-samples 2048 --out " + out);
  ASSERT_EQ(bake.exit_code, 0) << bake.out;
  EXPECT_NE(bake.out.find("lpv: 2 cascades of 8x8x8 cells"), std::string::npos) << bake.out;
  loader::BakeFile file;
  ASSERT_FALSE(file.open(out));
  ASSERT_EQ(file.lpv_cascades().size(), 2u);
  EXPECT_EQ(file.lpv_cascades()[0].desc().iterations, 16u);
  const loader::Rgb e = file.sample_lpv({0.f, 1.f, 0.f}, {0.f, 1.f, 0.f});
  EXPECT_GT(e[0], 0.f);
  const test::RunResult verify = test::run_gibake("verify " + out + " --scene " + scene);
  EXPECT_EQ(verify.exit_code, 0) << verify.out;
  // --lpv alone: a bake file with LPV sections and no DDGI volume, which the loader and verify accept.
  const test::RunResult lpv_only = test::run_gibake(scene + " --lpv --lpv-res 8 --lpv-samples 2048 --out " + out);
  ASSERT_EQ(lpv_only.exit_code, 0) << lpv_only.out;
  loader::BakeFile only;
  ASSERT_FALSE(only.open(out));
  EXPECT_TRUE(only.ddgi_volumes().empty());
  ASSERT_EQ(only.lpv_cascades().size(), 1u);
  EXPECT_EQ(only.lpv_cascades()[0].desc().flags & GIBAKE_LPV_FLAG_OCCLUSION, GIBAKE_LPV_FLAG_OCCLUSION);  // the voxel grid
  EXPECT_EQ(test::run_gibake("verify " + out + " --scene " + scene).exit_code, 0);
  const test::RunResult too_coarse = test::run_gibake(scene + " --ddgi --lpv --lpv-res 2 --out " + out);
  EXPECT_EQ(too_coarse.exit_code, 1);
  EXPECT_NE(too_coarse.out.find("--lpv-res: expected a whole number in 4..512, got '2'"), std::string::npos) << too_coarse.out;
  std::filesystem::remove_all(dir);
}

}  // namespace
