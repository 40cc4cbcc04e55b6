// The GLSL blend of several DDGI volumes (gibake_ddgi_blended_irradiance in
// io/loader/include/gibake/ddgi_sample.glsl, through ddgi_blend_accessors.comp) on lavapipe against
// the loader's BakeFile::sample_ddgi on the same multi-volume files, query by query: the irradiance
// and whether the point lies in some volume. As for the one-volume sampler
// (ddgi_sample_glsl_test.cpp), only the device's rounding of divisions and square roots may differ:
// every RGB value within 1e-5 x the largest value of the query set on any device, and identical to
// the bit on lavapipe (IEEE division and square root). Files: a coarse volume holding a finer one
// and a finer one still (priority unlike file order), one beside them sharing a fade band, an
// inactive corner in the finest (skipped there), f32 and f16 sections; each probe's irradiance from
// its irradiance atlas tile (the default) and from its SH.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "gibake/loader.hpp"
#include "kernels/shaders/ddgi_blend_accessors_spv.h"
#include "kernels/shaders/ddgi_blend_indexed_spv.h"
#include "tests/loader/multi_volume.h"
#include "tests/loader/synthetic.h"
#include "tests/vulkan/ddgi_decoded.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

using loader::Vec3;

struct BlendParams {  // ddgi_blend_accessors.comp's Params (std430)
  float smooth_backface, normal_bias, normal_bias_cells, variance_floor, min_weight;
  uint32_t use_visibility, use_irradiance_atlas;
  float behind_fade;
  uint32_t volume_count, query_count;
};
static_assert(sizeof(BlendParams) == 40, "std430 layout");

struct Query {
  Vec3 p, n;
};

std::vector<uint32_t> words(const void* data, size_t bytes) {
  std::vector<uint32_t> w(std::max<size_t>(1, (bytes + 3) / 4), 0u);
  if (bytes) std::memcpy(w.data(), data, bytes);
  return w;
}

// Every volume's decoded data, concatenated, and its GibakeDdgiVolume in priority order with the
// offsets of its data in the engine words (the kernels' bindings 0..5): the stored probes' SH (9
// coefficients each), states and offsets at one index, the slot maps after the states.
std::vector<std::vector<uint32_t>> volume_data(const loader::BakeFile& file) {
  test::DecodedDdgi a;
  a.sh_of_nine = true;
  std::vector<loader::GlslDdgiVolume> glsl(file.ddgi_volumes().size());
  for (size_t i = 0; i < file.ddgi_volumes().size(); ++i) {
    const loader::DdgiVolume& v = file.ddgi_volumes()[i];
    loader::GlslDdgiVolume& g = glsl[i];
    g = v.glsl_volume();
    g.engine[0] = uint32_t(a.irradiance.size() / 4);
    g.engine[1] = uint32_t(a.states.size());
    g.engine[2] = uint32_t(a.depth.size() / 2);
    g.engine[3] = uint32_t(a.slots.size());  // within the maps; moved past the states below
    a.append(v);
  }
  for (loader::GlslDdgiVolume& g : glsl) g.engine[3] += uint32_t(a.states.size());
  std::vector<uint32_t> states_then_slots = a.states;
  states_then_slots.insert(states_then_slots.end(), a.slots.begin(), a.slots.end());
  std::vector<loader::GlslDdgiVolume> ordered;
  for (uint32_t i : file.ddgi_priority()) ordered.push_back(glsl[i]);
  return {words(a.sh.data(), a.sh.size() * 4),
          words(states_then_slots.data(), states_then_slots.size() * 4),
          words(a.offsets.data(), a.offsets.size() * 4),
          words(a.depth.data(), a.depth.size() * 4),
          words(a.irradiance.data(), a.irradiance.size() * 4),
          words(ordered.data(), ordered.size() * sizeof(loader::GlslDdgiVolume))};
}

// The file's ddgi_volume_index payload as stored, and each file volume's priority rank
// (ddgi_blend_indexed.comp's bindings 9 and 10).
std::vector<std::vector<uint32_t>> index_data(const loader::BakeFile& file) {
  const int32_t s = file.ddgi_index().section();
  std::vector<uint32_t> ranks(file.ddgi_volumes().size());
  for (uint32_t r = 0; r < ranks.size(); ++r) ranks[file.ddgi_priority()[r]] = r;
  return {words(file.section_data(uint32_t(s)), size_t(file.sections()[size_t(s)].size)),
          words(ranks.data(), ranks.size() * 4)};
}

// `indexed`: gibake_ddgi_indexed_irradiance (ddgi_blend_indexed.comp) instead of the loop.
Status run_blend(vk::Context& ctx, const loader::BakeFile& file, const loader::SampleOptions& o,
                 const std::vector<Query>& queries, std::vector<float>& out, bool indexed = false) {
  BlendParams params{o.smooth_backface,
                     o.normal_bias,
                     o.normal_bias_cells,
                     o.variance_floor,
                     o.min_weight,
                     o.use_visibility ? 1u : 0u,
                     o.use_irradiance_atlas ? 1u : 0u,
                     o.behind_fade,
                     uint32_t(file.ddgi_volumes().size()),
                     uint32_t(queries.size())};
  std::vector<float> packed;
  for (const Query& q : queries)
    packed.insert(packed.end(), {q.p[0], q.p[1], q.p[2], 0.f, q.n[0], q.n[1], q.n[2], 0.f});
  std::vector<std::vector<uint32_t>> data = volume_data(file);
  data.push_back(words(&params, sizeof params));
  data.push_back(words(packed.data(), packed.size() * 4));
  data.push_back(std::vector<uint32_t>(queries.size() * 4, 0u));
  const size_t output = data.size() - 1;
  if (indexed)
    for (std::vector<uint32_t>& w : index_data(file)) data.push_back(std::move(w));
  std::vector<vk::Buffer> buffers(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    GIBAKE_TRY(ctx.create_buffer(data[i].size() * 4, buffers[i], "ddgi blend test"));
    GIBAKE_TRY(ctx.upload(buffers[i], data[i].data(), data[i].size() * 4));
  }
  vk::Pipeline pipeline;
  if (indexed)
    GIBAKE_TRY(ctx.create_pipeline(shaders::ddgi_blend_indexed_spv, sizeof(shaders::ddgi_blend_indexed_spv) / 4, 11, 0,
                                   pipeline, "ddgi_blend_indexed"));
  else
    GIBAKE_TRY(ctx.create_pipeline(shaders::ddgi_blend_accessors_spv, sizeof(shaders::ddgi_blend_accessors_spv) / 4, 9,
                                   0, pipeline, "ddgi_blend_accessors"));
  vk::Dispatch d;
  d.pipeline = &pipeline;
  for (const vk::Buffer& b : buffers) d.buffers.push_back(&b);
  d.groups[0] = uint32_t((queries.size() + 63) / 64);
  GIBAKE_TRY(ctx.run({d}));
  out.resize(queries.size() * 4);
  return ctx.download(buffers[output], out.data(), out.size() * 4);
}

DdgiResult volume(int nx, int ny, int nz, Vec3 grid_min, Vec3 spacing, uint32_t seed) {
  DdgiResult r = test::make_ddgi(nx, ny, nz, 2, seed);
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = grid_min[a];
    r.desc.spacing[a] = spacing[a];
    r.desc.grid_max[a] = grid_min[a] + spacing[a] * float(r.desc.counts[a] - 1);
  }
  for (size_t p = 0; p < r.states.size(); ++p) r.states[p] = p % 7 == 3 ? ProbeState::Inactive : ProbeState::Active;
  return r;
}

// Random points over the coarse volume and beyond it, a third of them in the finer volumes' fade
// bands, and far away; random unit normals.
std::vector<Query> make_queries(uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  auto unit = [&] {
    Vec3 n{g(rng), g(rng), g(rng)};
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return Vec3{n[0] / l, n[1] / l, n[2] / l};
  };
  std::vector<Query> q;
  for (int i = 0; i < count; ++i) {
    Vec3 p;
    if (i % 3 == 0) {  // around the finer volumes' faces
      for (int a = 0; a < 3; ++a) p[a] = 1.6f + 2.8f * u(rng);
      const int a = i % 9 / 3;
      p[a] = (u(rng) < 0.5f ? 1.75f : 4.25f) + (u(rng) - 0.5f) * 0.6f;
    } else {
      for (int a = 0; a < 3; ++a) p[a] = -4.f + 20.f * u(rng);
    }
    q.push_back({p, unit()});
  }
  for (const Vec3& far : {Vec3{1e4f, -1e4f, 3e3f}, Vec3{-50.f, 0.5f, 0.5f}, Vec3{30.f, 2.f, 2.f}})
    q.push_back({far, unit()});
  return q;
}

class GlslBlend : public ::testing::Test {
 protected:
  void SetUp() override { GIBAKE_OPEN_VULKAN_OR_SKIP(ctx_); }
  void TearDown() override {
    if (ctx_) {
      GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx_);
    }
  }
  void check(const std::vector<const DdgiResult*>& volumes, FloatPrecision precision, const loader::SampleOptions& o,
             const std::string& label, bool indexed = false) {
    BakeFileOptions options;
    options.sh = precision;
    options.atlas = precision;
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(test::multi_volume_bytes(volumes, options, bytes).is_ok());
    loader::BakeFile file;
    ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
    const std::vector<Query> queries = make_queries(53, 1500);
    std::vector<float> cpu;
    std::vector<int> cpu_inside;
    float peak = 0.f;
    size_t mixed = 0, outside = 0, listed = 0, source_matters = 0;
    loader::SampleOptions other_source = o;  // irradiance atlas <-> SH: proof the queries read the switch
    other_source.use_irradiance_atlas = !o.use_irradiance_atlas;
    for (const Query& q : queries) {
      uint32_t cell = 0;
      listed += file.ddgi_index().cell_of(q.p, cell) && file.ddgi_index().list_size(cell) > 0;
      loader::Rgb e;
      cpu_inside.push_back(file.sample_ddgi(q.p, q.n, e, o));
      cpu.insert(cpu.end(), e.begin(), e.end());
      for (float x : e) peak = std::max(peak, x);
      loader::Rgb other;
      file.sample_ddgi(q.p, q.n, other, other_source);
      source_matters += other != e;
      size_t weighted = 0;
      for (const loader::DdgiVolume& v : file.ddgi_volumes()) weighted += v.blend_weight(q.p) > 0.f;
      mixed += weighted > 1;
      outside += cpu_inside.back() == 0;
    }
    std::vector<float> gpu;
    if (indexed) {
      ASSERT_TRUE(file.ddgi_index().present()) << label;
      EXPECT_GT(listed, queries.size() / 2) << label << ": too few queries through the index";
    }
    const Status st = run_blend(*ctx_, file, o, queries, gpu, indexed);
    ASSERT_TRUE(st.is_ok()) << st.message();
    float largest = 0.f;
    size_t identical = 0, over = 0;
    for (size_t i = 0; i < queries.size(); ++i) {
      EXPECT_EQ(gpu[i * 4 + 3] == 1.f, cpu_inside[i] != 0) << label << " query " << i << ": inside";
      bool same = true;
      for (int k = 0; k < 3; ++k) {
        const float c = cpu[i * 3 + k], g = gpu[i * 4 + k];
        largest = std::max(largest, std::fabs(g - c));
        same = same && std::memcmp(&c, &g, 4) == 0;
        if (!(std::fabs(g - c) <= 1e-5f * peak) && ++over <= 5)
          ADD_FAILURE() << label << " query " << i << " channel " << k << ": GPU " << g << ", CPU " << c << " at ("
                        << queries[i].p[0] << ", " << queries[i].p[1] << ", " << queries[i].p[2] << ")";
      }
      identical += same;
    }
    EXPECT_EQ(over, 0u) << label << ": values further than 1e-5 x " << peak << " lux from the CPU's";
    if (ctx_->device().is_lavapipe()) {
      EXPECT_EQ(identical, queries.size()) << label << ": lavapipe must reproduce the CPU blend to the bit";
    }
    EXPECT_GT(source_matters, queries.size() / 2) << label << ": the irradiance atlas must matter (CPU)";
    if (volumes.size() > 1) {
      EXPECT_GT(mixed, queries.size() / 10) << label << ": too few queries where volumes blend";
      EXPECT_GT(outside, 10u) << label << ": too few queries outside every volume";
    }
    std::printf(
        "%-28s %zu queries (%zu where volumes blend, %zu outside all, %zu in an indexed cell, %zu atlas/SH "
        "differ), peak %.6g lux: largest |GPU-CPU| %.3g, bit-identical %zu\n",
        label.c_str(), queries.size(), mixed, outside, listed, source_matters, peak, largest, identical);
  }
  std::unique_ptr<vk::Context> ctx_;
};

TEST_F(GlslBlend, NestedAndSideBySideVolumes) {
  const DdgiResult coarse = volume(6, 6, 6, {0.f, 0.f, 0.f}, {2.f, 2.f, 2.f}, 501);
  DdgiResult fine = volume(5, 5, 5, {2.f, 2.f, 2.f}, {0.5f, 0.5f, 0.5f}, 502);
  for (int z = 0; z < 2; ++z)  // the corner cell x, y, z in [2, 2.5] has no active probe: skipped there
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) fine.states[size_t(x + 5 * (y + 5 * z))] = ProbeState::Inactive;
  const DdgiResult finest = volume(4, 3, 4, {2.6f, 2.4f, 2.5f}, {0.3f, 0.4f, 0.3f}, 503);
  const DdgiResult beside = volume(3, 4, 3, {10.5f, 1.f, 1.f}, {2.f, 2.f, 2.f}, 504);  // same spacing: file order
  const std::vector<const DdgiResult*> all{&coarse, &beside, &fine, &finest};
  check(all, FloatPrecision::Full, {}, "4 volumes f32");
  check(all, FloatPrecision::Half, {}, "4 volumes f16");
  loader::SampleOptions off;
  off.use_visibility = false;
  off.smooth_backface = 0.f;
  check(all, FloatPrecision::Full, off, "4 volumes, hard, no visibility");
  loader::SampleOptions sh;
  sh.use_irradiance_atlas = false;
  check(all, FloatPrecision::Half, sh, "4 volumes f16 SH");
  check({&fine}, FloatPrecision::Full, {}, "1 volume");
}

// A fine volume whose probes' depth moments put occluders 5-60 cm away, so that at many points no
// probe of its cell sees the point well (a sight under GIBAKE_DDGI_FULL_SIGHT): the blend hands
// those points to the coarse volume in proportion, on the GPU as on the CPU.
TEST_F(GlslBlend, AVolumeWhoseProbesBarelySeeThePoint) {
  const DdgiResult coarse = volume(6, 6, 6, {0.f, 0.f, 0.f}, {2.f, 2.f, 2.f}, 531);
  DdgiResult fine = volume(5, 5, 5, {2.f, 2.f, 2.f}, {0.5f, 0.5f, 0.5f}, 532);
  std::mt19937 rng(533);
  std::uniform_real_distribution<float> u(0.05f, 0.6f);
  for (size_t i = 0; i + 1 < fine.depth_atlas.size(); i += 2) {
    fine.depth_atlas[i] = u(rng);
    fine.depth_atlas[i + 1] = fine.depth_atlas[i] * fine.depth_atlas[i] + 1e-4f;
  }
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(test::multi_volume_bytes({&coarse, &fine}, BakeFileOptions{}, bytes).is_ok());
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
  size_t unseen = 0;
  for (const Query& q : make_queries(53, 1500)) {
    loader::ProbeWeight w[8];
    const uint32_t count = file.ddgi_volumes()[1].probe_weights(q.p, q.n, w);
    float sight = 0.f;
    for (uint32_t k = 0; k < count; ++k) sight = std::max(sight, w[k].backface * w[k].visibility);
    unseen += count > 0 && sight < GIBAKE_DDGI_FULL_SIGHT;
  }
  EXPECT_GT(unseen, 50u) << "too few queries the fine volume barely sees";
  check({&coarse, &fine}, FloatPrecision::Full, {}, "barely seen f32");
  loader::SampleOptions hard;
  hard.smooth_backface = 0.f;  // sight 0 where every probe is behind the surface
  check({&coarse, &fine}, FloatPrecision::Half, hard, "barely seen f16, hard", true);
}

// gibake_ddgi_indexed_irradiance (the file's volume index, format 1.4) against the CPU: the four
// volumes above, and a coarse grid under 20 small overlapping volumes of unlike spacings.
// A near-surface volume stored sparse (format 1.5) inside a coarse one and beside a dense fine one:
// the blend reads its probes through its slot map, loop and index alike.
TEST_F(GlslBlend, SparseVolumeAmongDenseOnes) {
  const DdgiResult coarse = volume(6, 6, 6, {0.f, 0.f, 0.f}, {2.f, 2.f, 2.f}, 521);
  DdgiResult near = volume(7, 6, 7, {2.f, 2.f, 2.f}, {0.4f, 0.4f, 0.4f}, 522);
  for (size_t p = 0; p < near.states.size(); ++p)  // two in three left out, as far from surfaces
    if (p % 3 != 1) near.states[p] = ProbeState::Inactive;
  near.sparse = true;
  const DdgiResult beside = volume(3, 4, 3, {10.5f, 1.f, 1.f}, {2.f, 2.f, 2.f}, 523);
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(test::multi_volume_bytes({&coarse, &near, &beside}, BakeFileOptions{}, bytes).is_ok());
  loader::BakeFile file;
  ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
  ASSERT_TRUE(file.ddgi_volumes()[1].sparse());
  EXPECT_EQ(file.header().version_minor, 5u);
  check({&coarse, &near, &beside}, FloatPrecision::Full, {}, "sparse among dense f32");
  check({&coarse, &near, &beside}, FloatPrecision::Half, {}, "sparse among dense f16, indexed", true);
}

TEST_F(GlslBlend, IndexedVolumes) {
  const DdgiResult coarse = volume(6, 6, 6, {0.f, 0.f, 0.f}, {2.f, 2.f, 2.f}, 501);
  DdgiResult fine = volume(5, 5, 5, {2.f, 2.f, 2.f}, {0.5f, 0.5f, 0.5f}, 502);
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) fine.states[size_t(x + 5 * (y + 5 * z))] = ProbeState::Inactive;
  const DdgiResult finest = volume(4, 3, 4, {2.6f, 2.4f, 2.5f}, {0.3f, 0.4f, 0.3f}, 503);
  const DdgiResult beside = volume(3, 4, 3, {10.5f, 1.f, 1.f}, {2.f, 2.f, 2.f}, 504);
  check({&coarse, &beside, &fine, &finest}, FloatPrecision::Full, {}, "4 volumes indexed f32", true);
  check({&coarse, &beside, &fine, &finest}, FloatPrecision::Half, {}, "4 volumes indexed f16", true);
  loader::SampleOptions sh;
  sh.use_irradiance_atlas = false;
  check({&coarse, &beside, &fine, &finest}, FloatPrecision::Full, sh, "4 volumes indexed f32 SH", true);
  std::vector<DdgiResult> many{coarse};
  std::mt19937 rng(61);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (uint32_t k = 0; k < 20; ++k) {
    const float s = 0.3f + 0.6f * u(rng);
    many.push_back(volume(3 + int(k % 2), 3, 2 + int(k % 3), {9.f * u(rng), 9.f * u(rng), 9.f * u(rng)},
                          {s, s, s * 1.2f}, 510 + k));
  }
  std::vector<const DdgiResult*> all;
  for (const DdgiResult& r : many) all.push_back(&r);
  check(all, FloatPrecision::Full, {}, "21 volumes indexed f32", true);
  loader::SampleOptions off;
  off.use_visibility = false;
  off.smooth_backface = 0.f;
  check(all, FloatPrecision::Full, off, "21 volumes indexed, hard", true);
}

}  // namespace
}  // namespace gibake
