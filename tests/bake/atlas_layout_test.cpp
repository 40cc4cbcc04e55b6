// Atlas layout with Y-planes wrapped onto more rows (format 1.1): the bake keeps atlases within
// --max-atlas-width, moves every tile as a whole, and the loader finds the same tiles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <set>
#include <utility>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "kernels/octahedral.h"
#include "tests/bake/scene_builders.h"

using namespace gibake;

namespace {

// A lit room with a block in it, a 4x6x2 grid (narrow in X, many Y-planes).
Scene lit_room() {
  Scene scene;
  test::add_box(scene, {-3, 0, -3}, {3, 3, 3}, /*inward=*/true, test::add_material(scene, 0.7f));
  test::add_box(scene, {-0.5f, 0, -0.5f}, {0.5f, 1.5f, 0.5f}, /*inward=*/false, test::add_material(scene, 0.4f));
  test::add_quad(scene, {-2, 2.99f, -2}, {-1, 2.99f, -2}, {-1, 2.99f, -1}, {-2, 2.99f, -1}, {0, -1, 0},
                 test::add_material(scene, 0.f, 20.f));
  return scene;
}

DdgiSettings small_grid(int max_atlas_width) {
  DdgiSettings s;
  s.grid.counts = {4, 6, 2};
  s.grid.explicit_bounds = true;
  s.grid.grid_min = {-2.5f, 0.25f, -2.5f};
  s.grid.grid_max = {2.5f, 2.75f, 2.5f};
  s.rays = 64;
  s.bounces = 1;
  s.max_atlas_width = max_atlas_width;
  return s;
}

// The lit room baked twice: atlases in one band (k = Y = 6) and wrapped to 2 planes per band.
bool bake_flat_and_wrapped(DdgiResult& flat, DdgiResult& wrapped) {
  const Scene scene = lit_room();
  DdgiReport rf, rw;
  return bake_ddgi(scene, small_grid(1 << 20), Context{}, flat, rf).is_ok() &&
         bake_ddgi(scene, small_grid(4 * 2 * 18), Context{}, wrapped, rw).is_ok();
}

kernels::AtlasLayout layout_of(const DdgiResult& r, int res) {
  kernels::AtlasLayout l;
  for (int a = 0; a < 3; ++a) l.counts[a] = r.desc.counts[a];
  l.res = res;
  l.planes_per_row = r.atlas_planes_per_row;
  return l;
}

// Number of texels (borders included, every channel) of all tiles that differ between two atlases
// of the same probes in the layouts `la` and `lb`.
size_t differing_tile_texels(const std::vector<float>& a, int width_a, const kernels::AtlasLayout& la,
                             const std::vector<float>& b, int width_b, const kernels::AtlasLayout& lb, int channels,
                             int probes) {
  size_t differ = 0;
  for (int p = 0; p < probes; ++p) {
    int ax, ay, bx, by;
    la.tile_origin(p, ax, ay);
    lb.tile_origin(p, bx, by);
    for (int ty = 0; ty < la.tile(); ++ty)
      for (int tx = 0; tx < la.tile(); ++tx)
        for (int c = 0; c < channels; ++c)
          differ += a[(size_t(ay + ty) * width_a + ax + tx) * channels + c] !=
                    b[(size_t(by + ty) * width_b + bx + tx) * channels + c];
  }
  return differ;
}

}  // namespace

// The chosen k keeps the atlas within the limit with as few bands as possible, spread evenly; the
// tiles of all probes are distinct and inside the atlas.
TEST(AtlasLayout, WrapsPlanesToStayWithinMaxWidth) {
  EXPECT_EQ(kernels::atlas_planes_per_row(32, 32, 18, 16384), 16);  // 2 bands of 16: 9216 wide
  EXPECT_EQ(kernels::atlas_planes_per_row(64, 16, 18, 16384), 8);   // 14 would fit; 2 bands of 8
  EXPECT_EQ(kernels::atlas_planes_per_row(10, 10, 18, 16384), 10);  // fits as one band
  EXPECT_EQ(kernels::atlas_planes_per_row(1000, 4, 18, 16384), 1);  // not even one plane fits
  for (int k : {1, 3, 5, 7}) {
    kernels::AtlasLayout l;
    l.counts[0] = 3;
    l.counts[1] = 7;
    l.counts[2] = 2;
    l.res = 16;
    l.planes_per_row = k;
    EXPECT_EQ(l.width(), 3 * k * 18);
    EXPECT_EQ(l.height(), 2 * ((7 + k - 1) / k) * 18);
    std::set<std::pair<int, int>> seen;
    for (int p = 0; p < 3 * 7 * 2; ++p) {
      int ox, oy;
      l.tile_origin(p, ox, oy);
      EXPECT_EQ(ox % 18, 0);
      EXPECT_EQ(oy % 18, 0);
      EXPECT_LE(ox + 18, l.width());
      EXPECT_LE(oy + 18, l.height());
      EXPECT_TRUE(seen.insert({ox, oy}).second) << "k " << k << " probe " << p;
    }
  }
}

// The same bake with and without wrapping: identical SH, and every tile (borders included) of both
// atlases holds the same texels, only at its wrapped place; the wrapped atlas fits the limit.
TEST(AtlasLayout, WrappedBakeMovesWholeTiles) {
  DdgiResult flat, wrapped;
  ASSERT_TRUE(bake_flat_and_wrapped(flat, wrapped));
  EXPECT_EQ(flat.atlas_planes_per_row, 6);
  EXPECT_EQ(wrapped.atlas_planes_per_row, 2);
  EXPECT_EQ(flat.depth_width, 4 * 6 * 18);
  EXPECT_EQ(wrapped.depth_width, 4 * 2 * 18);
  EXPECT_EQ(wrapped.depth_height, 2 * 3 * 18);
  EXPECT_EQ(wrapped.irradiance_width, 4 * 2 * 10);
  EXPECT_EQ(flat.sh, wrapped.sh);
  const int probes = flat.desc.probe_count();
  EXPECT_EQ(differing_tile_texels(flat.irradiance_atlas, flat.irradiance_width, layout_of(flat, kIrradianceTexels),
                                  wrapped.irradiance_atlas, wrapped.irradiance_width,
                                  layout_of(wrapped, kIrradianceTexels), 4, probes),
            0u);
  EXPECT_EQ(
      differing_tile_texels(flat.depth_atlas, flat.depth_width, layout_of(flat, kDepthTexels), wrapped.depth_atlas,
                            wrapped.depth_width, layout_of(wrapped, kDepthTexels), 2, probes),
      0u);
}

// Written and read back, the loader reports the layout, finds each probe's tile where the bake put
// it, and its sampler (which reads the depth atlas for visibility) gives the same irradiance from
// the wrapped file as from the flat one -- to 1e-5 relative: the texels are identical, but the
// bilinear position is computed from a different tile origin, which moves its last bits.
TEST(AtlasLayout, LoaderReadsWrappedFiles) {
  DdgiResult flat, wrapped;
  ASSERT_TRUE(bake_flat_and_wrapped(flat, wrapped));
  BakeFileOptions full;
  full.atlas = FloatPrecision::Full;
  std::vector<uint8_t> flat_bytes, wrapped_bytes;
  BakeOutputs out;
  out.ddgi = &flat;
  ASSERT_TRUE(build_bake_file(out, full, flat_bytes));
  out.ddgi = &wrapped;
  ASSERT_TRUE(build_bake_file(out, full, wrapped_bytes));
  loader::BakeFile ff, wf;
  ASSERT_TRUE(ff.open(std::move(flat_bytes)).ok());
  ASSERT_TRUE(wf.open(std::move(wrapped_bytes)).ok());
  const loader::DdgiVolume& fv = ff.ddgi_volumes().at(0);
  const loader::DdgiVolume& wv = wf.ddgi_volumes().at(0);
  EXPECT_EQ(fv.atlas_planes_per_row(), 6u);
  EXPECT_EQ(wv.atlas_planes_per_row(), 2u);
  const kernels::AtlasLayout wd = layout_of(wrapped, kDepthTexels);
  for (uint32_t p = 0; p < wv.probe_count(); ++p) {
    int ox, oy;
    wd.tile_origin(int(p), ox, oy);
    const std::array<uint32_t, 2> o = wv.tile_origin(p, kDepthTexels);
    EXPECT_EQ(o[0], uint32_t(ox));
    EXPECT_EQ(o[1], uint32_t(oy));
    EXPECT_EQ(wv.depth_texel(o[0] + 5, o[1] + 7),
              fv.depth_texel(fv.tile_origin(p, kDepthTexels)[0] + 5, fv.tile_origin(p, kDepthTexels)[1] + 7));
  }
  int compared = 0;
  for (int i = 0; i < 200; ++i) {
    const loader::Vec3 pos{-2.f + 0.02f * i, 0.3f + 0.012f * i, 2.f - 0.017f * i};
    const loader::Vec3 n{0.f, 1.f, 0.f};
    const loader::Rgb a = fv.sample_irradiance(pos, n), b = wv.sample_irradiance(pos, n);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-5f * std::max(1.f, a[c])) << i;
    compared += a[0] > 0.f;
  }
  EXPECT_GT(compared, 100);  // the points are lit, so the comparison means something
}

// A k larger than Y (or an atlas whose size does not match k) is refused as a bad volume, not
// read out of bounds; k = 0 (a 1.0 file) means one band and reads the flat layout.
TEST(AtlasLayout, LoaderRefusesImpossibleLayouts) {
  const Scene scene = lit_room();
  DdgiResult flat;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, small_grid(1 << 20), Context{}, flat, rep));
  BakeOutputs out;
  out.ddgi = &flat;
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(build_bake_file(out, BakeFileOptions{}, bytes));
  loader::BakeFile probe;
  ASSERT_TRUE(probe.open_borrowed(bytes.data(), bytes.size()).ok());
  uint64_t at = 0;
  for (const gibake_section_entry& e : probe.sections())
    if (e.type == GIBAKE_SECTION_DDGI_VOLUME) at = e.offset + offsetof(gibake_ddgi_volume, atlas_planes_per_row);
  ASSERT_GT(at, 0u);
  auto open_with_k = [&](uint32_t k) {
    std::vector<uint8_t> patched = bytes;
    std::memcpy(&patched[at], &k, 4);
    loader::BakeFile f;
    return f.open(std::move(patched), loader::LoadOptions{false}).code;  // checksums no longer match
  };
  EXPECT_EQ(open_with_k(6), loader::ErrorCode::Ok);
  EXPECT_EQ(open_with_k(0), loader::ErrorCode::Ok);
  EXPECT_EQ(open_with_k(7), loader::ErrorCode::BadVolume);
  EXPECT_EQ(open_with_k(2), loader::ErrorCode::BadVolume);  // the atlas is 6 planes wide, not 2
}
