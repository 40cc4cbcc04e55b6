// The 1.3 sections through the writer and the loader: a hand-made volume round-trips bit for bit
// (f32) and within float16 rounding (f16), the level offsets and clamped sampling behave as
// FORMAT.md says, and every inconsistency the loader must catch gives its documented error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "io/bakefile/bake_file.h"
#include "tests/loader/test_util.h"

namespace gibake {
namespace {

VxgiResult make_result(std::array<int32_t, 3> dims) {
  VxgiResult r;
  VxgiClipmap c;
  c.grid_min = {-1.f, 0.f, 2.f};
  c.voxel_size = 0.25f;
  c.dims = dims;
  const int levels = vxgi_full_levels(dims);
  for (int l = 0; l < levels; ++l) {
    const auto d = vxgi_level_dims(dims, l);
    std::vector<float> v(size_t(kVxgiFaces) * size_t(d[0]) * size_t(d[1]) * size_t(d[2]) * 4);
    for (size_t i = 0; i < v.size(); ++i) v[i] = i % 4 == 3 ? 0.5f : float((i * 7 + size_t(l)) % 13) * 0.25f;
    c.levels.push_back(std::move(v));
  }
  c.sdf.assign(c.voxel_count(), 0.5f);
  c.diffuse_scale = 1.25f;
  c.calibration_error = 0.1f;
  c.calibration_points = 7;
  r.clipmaps.push_back(std::move(c));
  r.sky = {0.1f, 0.2f, 0.3f};
  return r;
}

std::vector<uint8_t> build(const VxgiResult& r, FloatPrecision p = FloatPrecision::Full) {
  BakeOutputs o;
  o.vxgi = &r;
  BakeFileOptions options;
  options.vxgi = p;
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(build_bake_file(o, options, bytes).is_ok());
  return bytes;
}

TEST(VxgiFormat, RoundTripsEveryLevelAndFace) {
  const VxgiResult r = make_result({5, 3, 4});
  for (FloatPrecision p : {FloatPrecision::Full, FloatPrecision::Half}) {
    const std::vector<uint8_t> bytes = build(r, p);
    loader::BakeFile f;
    ASSERT_FALSE(f.open_borrowed(bytes.data(), bytes.size()));
    ASSERT_EQ(f.vxgi_volumes().size(), 1u);
    const loader::VxgiVolume& v = f.vxgi_volumes()[0];
    EXPECT_EQ(f.header().version_minor, GIBAKE_VERSION_MINOR_VXGI);
    EXPECT_EQ(v.levels(), 4u);  // 5x3x4 -> 3x2x2 -> 2x1x1 -> 1x1x1
    EXPECT_EQ(v.desc().diffuse_scale, 1.25f);
    EXPECT_EQ(v.desc().calibration_points, 7u);
    EXPECT_TRUE(v.has_sdf());
    const VxgiClipmap& c = r.clipmaps[0];
    for (uint32_t l = 0; l < v.levels(); ++l) {
      const auto d = v.level_dims(l);
      for (uint32_t face = 0; face < 6; ++face)
        for (int32_t z = 0; z < d[2]; ++z)
          for (int32_t y = 0; y < d[1]; ++y)
            for (int32_t x = 0; x < d[0]; ++x) {
              const loader::Rgba t = v.texel(l, face, x, y, z);
              const size_t cell = size_t(x) + size_t(d[0]) * (size_t(y) + size_t(d[1]) * size_t(z));
              const size_t cells = size_t(d[0]) * size_t(d[1]) * size_t(d[2]);
              for (int k = 0; k < 4; ++k) {
                const float want = c.levels[l][(face * cells + cell) * 4 + size_t(k)];
                if (p == FloatPrecision::Full) EXPECT_EQ(t[size_t(k)], want);
                else EXPECT_NEAR(t[size_t(k)], want, 1e-3f * std::max(1.f, want));
              }
            }
    }
    EXPECT_EQ(v.texel(0, 0, -1, 0, 0)[3], 0.f);  // outside: zero
    EXPECT_EQ(v.texel(0, 6, 0, 0, 0)[3], 0.f);   // no face 6
    // Clamp-to-edge: far outside along x reads the edge texel.
    const loader::Rgba edge = v.sample(0, 0, {100.f, 0.125f, 2.125f});
    EXPECT_EQ(edge[0], v.texel(0, 0, 4, 0, 0)[0]);
    EXPECT_NEAR(v.sdf({0.f, 0.3f, 2.4f}), 0.5f, 1e-3f);
  }
}

TEST(VxgiFormat, LoaderRejectsInconsistentVolumes) {
  const std::vector<uint8_t> good = build(make_result({4, 4, 4}));
  auto expect_error = [&](auto edit, loader::ErrorCode code) {
    std::vector<uint8_t> bytes = good;
    edit(bytes);
    test::reseal(bytes);
    loader::BakeFile f;
    const loader::Error e = f.open_borrowed(bytes.data(), bytes.size(), loader::LoadOptions{false});
    EXPECT_EQ(e.code, code) << e.message;
  };
  auto desc = [](std::vector<uint8_t>& b) {
    return reinterpret_cast<gibake_vxgi_volume*>(b.data() + test::table_entry(b, 0)->offset);
  };
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->faces = 5; }, loader::ErrorCode::BadVolume);
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->levels = 4; }, loader::ErrorCode::BadVolume);  // full chain is 3
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->dims[1] = 0; }, loader::ErrorCode::BadVolume);
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->voxel_size = -1.f; }, loader::ErrorCode::BadVolume);
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->diffuse_scale = 0.f; }, loader::ErrorCode::BadVolume);
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->clipmap_index = 1; }, loader::ErrorCode::BadVolume);
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->sky[0] = NAN; }, loader::ErrorCode::BadVolume);
  expect_error([&](std::vector<uint8_t>& b) { desc(b)->levels = 2; }, loader::ErrorCode::BadVolume);  // count mismatch
  expect_error([&](std::vector<uint8_t>& b) { test::table_entry(b, 1)->group = 5; }, loader::ErrorCode::BadVolume);
  expect_error([&](std::vector<uint8_t>& b) { test::table_entry(b, 1)->type = 99; }, loader::ErrorCode::MissingSection);
  expect_error([&](std::vector<uint8_t>& b) { test::table_entry(b, 2)->type = GIBAKE_SECTION_VXGI_RADIANCE; },
               loader::ErrorCode::BadElementFormat);  // the f16 SDF is no RGBA payload
  // With the checksums on, a flipped payload byte is caught.
  std::vector<uint8_t> bytes = good;
  bytes[test::table_entry(bytes, 1)->offset + 3] ^= 0x40;
  loader::BakeFile f;
  EXPECT_EQ(f.open_borrowed(bytes.data(), bytes.size()).code, loader::ErrorCode::SectionChecksum);
}

}  // namespace
}  // namespace gibake
