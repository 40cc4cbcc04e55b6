// The GLSL sampler engines include (io/loader/include/gibake/ddgi_sample.glsl) on lavapipe against
// the loader's CPU sampler (DdgiVolume::sample_irradiance) on the same bake file, query by query:
// ddgi_sample.comp reads the file's section payloads as stored (f32 and f16), and
// ddgi_sample_accessors.comp reads data the loader decoded through engine-defined accessors, both
// with the irradiance atlas as the fifth.
// Both follow the CPU's operations in its order (`precise`); what may differ is only how the
// device rounds divisions and square roots, so every RGB value must be within 1e-5 x the largest
// value of the query set (absolute) on any device, and on lavapipe (IEEE division and square root)
// identical to the bit. The test prints the largest difference and how many queries match to the
// bit. Cases: wrapped and unwrapped atlases, each probe's irradiance from its irradiance atlas tile
// (the default) and from its SH (use_irradiance_atlas off, or no atlas), SH orders 1 and 2,
// inactive probes (some cells entirely), visibility on and off, hard back faces, no depth atlas,
// one-probe axes, points at probes, on cell planes, near and far outside the grid, and a baked
// Cornell box (irradiance atlas and SH) with its depth tiles as baked and coarsened (--depth-tile 8
// and 4).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/depth_tiles.h"
#include "bake/pipeline/devices.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "io/gltf/import.h"
#include "kernels/shaders/ddgi_sample_accessors_spv.h"
#include "kernels/shaders/ddgi_sample_spv.h"
#include "tests/loader/synthetic.h"
#include "tests/vulkan/ddgi_decoded.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

using loader::Vec3;

// The kernels' Params block (std430): GibakeDdgiVolume, GibakeSampleOptions, the query count.
struct Params {
  loader::GlslDdgiVolume volume;
  float smooth_backface, normal_bias, normal_bias_cells, variance_floor, min_weight;
  uint32_t use_visibility, use_irradiance_atlas;
  float behind_fade;
  uint32_t query_count;
};
static_assert(offsetof(Params, smooth_backface) == 96 && offsetof(Params, query_count) == 128 && sizeof(Params) == 132,
              "std430 layout");

struct Query {
  Vec3 p, n;
};

Vec3 unit(float x, float y, float z) {
  const float l = std::sqrt(x * x + y * y + z * z);
  return {x / l, y / l, z / l};
}

// Points a renderer may ask for: at every probe (rest and relocated), on the cell planes between
// probes, random ones over the grid and 1.5 cells beyond it, and far away; random unit normals and
// the axes.
std::vector<Query> make_queries(const loader::DdgiVolume& v, uint32_t seed, int random_points) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  const gibake_ddgi_volume& d = v.desc();
  const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  auto normal = [&](int i) { return i % 3 == 0 ? axes[(i / 3) % 6] : unit(g(rng), g(rng), g(rng)); };
  std::vector<Query> q;
  int i = 0;
  for (uint32_t probe = 0; probe < v.probe_count(); ++probe) {
    q.push_back({v.probe_position(probe), normal(i++)});
    q.push_back({v.probe_rest_position(v.probe_coord(probe)), normal(i++)});
  }
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    const float margin = d.counts[a] > 1 ? 1.5f * d.spacing[a] : 1.f;
    lo[a] = d.grid_min[a] - margin;
    hi[a] = d.grid_max[a] + margin;
  }
  for (int k = 0; k < random_points; ++k) {
    Vec3 p{lo[0] + u(rng) * (hi[0] - lo[0]), lo[1] + u(rng) * (hi[1] - lo[1]), lo[2] + u(rng) * (hi[2] - lo[2])};
    if (k % 4 == 1) {  // on a cell plane of one axis
      const int a = k % 3;
      p[a] = d.grid_min[a] + float(int(u(rng) * float(d.counts[a]))) * d.spacing[a];
    }
    q.push_back({p, normal(i++)});
  }
  for (const Vec3& far : {Vec3{1e4f, -1e4f, 3e3f}, Vec3{-50.f, 0.5f, 0.5f}, Vec3{0.f, 80.f, -0.25f}})
    q.push_back({far, normal(i++)});
  return q;
}

std::vector<uint32_t> padded_words(const void* data, size_t bytes) {
  std::vector<uint32_t> words(std::max<size_t>(1, (bytes + 3) / 4), 0u);
  if (bytes) std::memcpy(words.data(), data, bytes);
  return words;
}

// The data the kernel's bindings 0..5 read: the section payloads as the file stores them, or
// (accessors) what the loader decodes.
std::vector<std::vector<uint32_t>> binding_data(const loader::BakeFile& file, const loader::DdgiVolume& v,
                                                bool accessors) {
  std::vector<std::vector<uint32_t>> b;
  if (!accessors) {
    for (uint32_t type : {GIBAKE_SECTION_DDGI_SH, GIBAKE_SECTION_DDGI_STATES, GIBAKE_SECTION_DDGI_OFFSETS,
                          GIBAKE_SECTION_DDGI_DEPTH, GIBAKE_SECTION_DDGI_IRRADIANCE, GIBAKE_SECTION_DDGI_PROBE_SLOTS}) {
      const int32_t s = v.section_index(type);
      b.push_back(s < 0 ? padded_words(nullptr, 0)
                        : padded_words(file.section_data(uint32_t(s)), size_t(file.sections()[size_t(s)].size)));
    }
    return b;
  }
  test::DecodedDdgi a;
  a.append(v);
  b.push_back(padded_words(a.sh.data(), a.sh.size() * 4));
  b.push_back(padded_words(a.states.data(), a.states.size() * 4));
  b.push_back(padded_words(a.offsets.data(), a.offsets.size() * 4));
  b.push_back(padded_words(a.depth.data(), a.depth.size() * 4));
  b.push_back(padded_words(a.irradiance.data(), a.irradiance.size() * 4));
  b.push_back(padded_words(a.slots.data(), a.slots.size() * 4));
  return b;
}

// Runs one of the two kernels over `queries`; RGB per query into `out`.
Status run_glsl(vk::Context& ctx, const loader::BakeFile& file, const loader::DdgiVolume& v,
                const loader::SampleOptions& o, const std::vector<Query>& queries, bool accessors,
                std::vector<float>& out) {
  Params params{};
  params.volume = v.glsl_volume();
  if (accessors) {
    params.volume.engine[0] = v.desc().depth_width;
    params.volume.engine[1] = v.desc().irradiance_width;
  }
  params.smooth_backface = o.smooth_backface;
  params.normal_bias = o.normal_bias;
  params.normal_bias_cells = o.normal_bias_cells;
  params.variance_floor = o.variance_floor;
  params.min_weight = o.min_weight;
  params.use_visibility = o.use_visibility ? 1u : 0u;
  params.use_irradiance_atlas = o.use_irradiance_atlas ? 1u : 0u;
  params.behind_fade = o.behind_fade;
  params.query_count = uint32_t(queries.size());
  std::vector<float> packed;
  for (const Query& q : queries)
    packed.insert(packed.end(), {q.p[0], q.p[1], q.p[2], 0.f, q.n[0], q.n[1], q.n[2], 0.f});
  std::vector<std::vector<uint32_t>> data = binding_data(file, v, accessors);
  data.push_back(padded_words(&params, sizeof params));
  data.push_back(padded_words(packed.data(), packed.size() * 4));
  data.push_back(std::vector<uint32_t>(queries.size() * 4, 0u));
  std::vector<vk::Buffer> buffers(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    GIBAKE_TRY(ctx.create_buffer(data[i].size() * 4, buffers[i], "ddgi sample test"));
    GIBAKE_TRY(ctx.upload(buffers[i], data[i].data(), data[i].size() * 4));
  }
  vk::Pipeline pipeline;
  if (accessors)
    GIBAKE_TRY(ctx.create_pipeline(shaders::ddgi_sample_accessors_spv, sizeof(shaders::ddgi_sample_accessors_spv) / 4,
                                   9, 0, pipeline, "ddgi_sample_accessors"));
  else
    GIBAKE_TRY(ctx.create_pipeline(shaders::ddgi_sample_spv, sizeof(shaders::ddgi_sample_spv) / 4, 9, 0, pipeline,
                                   "ddgi_sample"));
  vk::Dispatch d;
  d.pipeline = &pipeline;
  for (const vk::Buffer& b : buffers) d.buffers.push_back(&b);
  d.groups[0] = uint32_t((queries.size() + 63) / 64);
  GIBAKE_TRY(ctx.run({d}));
  std::vector<float> rgba(queries.size() * 4);
  GIBAKE_TRY(ctx.download(buffers.back(), rgba.data(), rgba.size() * 4));
  out.clear();
  for (size_t q = 0; q < queries.size(); ++q) out.insert(out.end(), {rgba[q * 4], rgba[q * 4 + 1], rgba[q * 4 + 2]});
  return Status::ok();
}

struct Agreement {
  float peak = 0.f, largest = 0.f;  // largest CPU value, largest |GPU - CPU|
  size_t queries = 0, identical = 0, lit = 0;
  // Queries the option changes (CPU): visibility, the back-face weight, the irradiance atlas, the
  // fade of probes behind the surface.
  size_t visibility_matters = 0, backface_matters = 0, atlas_matters = 0, behind_matters = 0;
};

// Both kernels against the CPU sampler on every query; returns the section-buffer kernel's figures.
Agreement compare(vk::Context& ctx, const loader::BakeFile& file, const loader::SampleOptions& o,
                  const std::vector<Query>& queries, const std::string& label) {
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  std::vector<float> cpu;
  Agreement a;
  a.queries = queries.size();
  for (const Query& q : queries) {
    const loader::Rgb e = v.sample_irradiance(q.p, q.n, o);
    cpu.insert(cpu.end(), e.begin(), e.end());
    for (float x : e) a.peak = std::max(a.peak, x);
    a.lit += e[0] > 0.f || e[1] > 0.f || e[2] > 0.f;
  }
  for (bool accessors : {false, true}) {
    std::vector<float> gpu;
    const Status st = run_glsl(ctx, file, v, o, queries, accessors, gpu);
    EXPECT_TRUE(st.is_ok()) << label << ": " << st.message();
    if (!st.is_ok()) return a;
    float largest = 0.f;
    size_t identical = 0, over = 0;
    const std::string what = label + (accessors ? " (accessors)" : " (sections)");
    for (size_t q = 0; q < queries.size(); ++q) {
      bool same = true;
      for (int k = 0; k < 3; ++k) {
        const float c = cpu[q * 3 + k], g = gpu[q * 3 + k];
        const float d = std::fabs(g - c);
        largest = std::max(largest, d);
        same = same && std::memcmp(&c, &g, 4) == 0;
        if (!(d <= 1e-5f * a.peak) && ++over <= 5)  // the first few in words, then a count
          ADD_FAILURE() << what << " query " << q << " channel " << k << ": GPU " << g << ", CPU " << c << " at ("
                        << queries[q].p[0] << ", " << queries[q].p[1] << ", " << queries[q].p[2] << ") normal ("
                        << queries[q].n[0] << ", " << queries[q].n[1] << ", " << queries[q].n[2] << ")";
      }
      identical += same;
    }
    EXPECT_EQ(over, 0u) << what << ": values further than 1e-5 x " << a.peak << " lux from the CPU's";
    // lavapipe divides and takes square roots as the CPU does (IEEE), so there the include must give
    // the CPU's bits: a lost `precise`, a reordered sum or a constant folded differently shows here
    // long before it reaches the tolerance.
    if (ctx.device().is_lavapipe()) {
      EXPECT_EQ(identical, queries.size()) << what << ": lavapipe must reproduce the CPU sampler to the bit";
    }
    std::printf(
        "%-34s %-9s %5zu queries (%zu lit), peak %.6g lux: largest |GPU-CPU| %.3g (%.3g of peak), "
        "bit-identical %zu\n",
        label.c_str(), accessors ? "accessors" : "sections", queries.size(), a.lit, a.peak, largest,
        a.peak > 0.f ? largest / a.peak : 0.f, identical);
    if (!accessors) {
      a.largest = largest;
      a.identical = identical;
    }
  }
  return a;
}

// Queries whose CPU irradiance changes between two option sets: proof that what an option
// switches (visibility, the back-face weight, the irradiance atlas) is exercised by the queries.
size_t differing(const loader::DdgiVolume& v, const std::vector<Query>& queries, const loader::SampleOptions& a,
                 const loader::SampleOptions& b) {
  size_t n = 0;
  for (const Query& q : queries) n += v.sample_irradiance(q.p, q.n, a) != v.sample_irradiance(q.p, q.n, b);
  return n;
}

loader::BakeFile open_bytes(const DdgiResult& r, FloatPrecision precision, std::vector<uint8_t>& bytes) {
  BakeOutputs outputs;
  outputs.ddgi = &r;
  BakeFileOptions options;
  options.sh = precision;
  options.atlas = precision;
  EXPECT_TRUE(build_bake_file(outputs, options, bytes).is_ok());
  loader::BakeFile file;
  const loader::Error e = file.open_borrowed(bytes.data(), bytes.size());
  EXPECT_FALSE(e) << e.message;
  return file;
}

// Re-lays a synthetic result's atlases for k planes per row (random texels again): the tiles a
// wrong layout would read hold different depths and irradiance, and each tile's irradiance varies
// with direction, so a wrong texel or weight shows.
void wrap_atlases(DdgiResult& r, int k, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const int bands = (r.desc.counts[1] + k - 1) / k;
  r.atlas_planes_per_row = k;
  r.irradiance_width = r.desc.counts[0] * k * (kIrradianceTexels + 2);
  r.irradiance_height = r.desc.counts[2] * bands * (kIrradianceTexels + 2);
  r.irradiance_atlas.clear();
  for (int i = 0; i < r.irradiance_width * r.irradiance_height; ++i) {
    for (int c = 0; c < 3; ++c) r.irradiance_atlas.push_back(0.5f + 60.f * u(rng));
    r.irradiance_atlas.push_back(1.f);
  }
  r.depth_width = r.desc.counts[0] * k * (kDepthTexels + 2);
  r.depth_height = r.desc.counts[2] * bands * (kDepthTexels + 2);
  r.depth_atlas.clear();
  for (int i = 0; i < r.depth_width * r.depth_height; ++i) {
    const float mean = 0.3f + 2.5f * u(rng);
    r.depth_atlas.push_back(mean);
    r.depth_atlas.push_back(mean * mean + 0.05f * u(rng));
  }
}

class GlslSampler : public ::testing::Test {
 protected:
  void SetUp() override { GIBAKE_OPEN_VULKAN_OR_SKIP(ctx_); }
  void TearDown() override {
    if (ctx_) {
      GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx_);
    }
  }
  Agreement check(const DdgiResult& r, FloatPrecision precision, const loader::SampleOptions& o,
                  const std::string& label, int random_points = 600) {
    std::vector<uint8_t> bytes;
    const loader::BakeFile file = open_bytes(r, precision, bytes);
    if (file.ddgi_volumes().empty()) {
      ADD_FAILURE() << label << ": no volume";
      return {};
    }
    const std::vector<Query> q = make_queries(file.ddgi_volumes()[0], 19, random_points);
    loader::SampleOptions no_visibility = o, hard = o, other_source = o, other_fade = o;
    no_visibility.use_visibility = false;
    other_fade.behind_fade = o.behind_fade > 0.f ? 0.f : 0.2f;
    hard.smooth_backface = o.smooth_backface > 0.f ? 0.f : 1.f;
    other_source.use_irradiance_atlas = !o.use_irradiance_atlas;
    const loader::DdgiVolume& v = file.ddgi_volumes()[0];
    Agreement a = compare(*ctx_, file, o, q, label);
    a.visibility_matters = differing(v, q, o, no_visibility);
    a.backface_matters = differing(v, q, o, hard);
    a.atlas_matters = differing(v, q, o, other_source);
    a.behind_matters = differing(v, q, o, other_fade);
    std::printf(
        "%-34s (CPU) visibility on/off changes %zu queries, the back-face weight %zu, atlas/SH %zu, "
        "the behind fade %zu\n",
        label.c_str(), a.visibility_matters, a.backface_matters, a.atlas_matters, a.behind_matters);
    return a;
  }
  std::unique_ptr<vk::Context> ctx_;
};

TEST_F(GlslSampler, WrappedAtlasFloat32AndFloat16) {
  DdgiResult r = test::make_ddgi(4, 5, 3, 2, 101);
  wrap_atlases(r, 2, 102);  // 5 planes in bands of 2, 2, 1
  const Agreement full = check(r, FloatPrecision::Full, {}, "4x5x3 L2 k=2 f32");
  EXPECT_GT(full.lit, full.queries / 2);
  EXPECT_GT(full.visibility_matters, full.queries / 4);
  EXPECT_GT(full.backface_matters, full.queries / 2);
  EXPECT_GT(full.atlas_matters, full.queries / 2);  // the default reads the irradiance atlas
  EXPECT_GT(full.behind_matters, full.queries / 2);  // most points have a probe behind them
  check(r, FloatPrecision::Half, {}, "4x5x3 L2 k=2 f16");
  const Agreement shared = check(r, FloatPrecision::SharedExponent, {}, "4x5x3 L2 k=2 rgb9e5");
  EXPECT_GT(shared.lit, shared.queries / 2);
  // The same file through the SH (use_irradiance_atlas off): both paths against the CPU.
  loader::SampleOptions sh;
  sh.use_irradiance_atlas = false;
  const Agreement through_sh = check(r, FloatPrecision::Full, sh, "4x5x3 L2 k=2 f32 SH");
  EXPECT_GT(through_sh.atlas_matters, through_sh.queries / 2);
  check(r, FloatPrecision::Half, sh, "4x5x3 L2 k=2 f16 SH");
  wrap_atlases(r, 5, 103);  // every plane in one band
  check(r, FloatPrecision::Half, {}, "4x5x3 L2 k=5 f16");
}

TEST_F(GlslSampler, VisibilityOffHardBackFacesAndLowerOrder) {
  DdgiResult r = test::make_ddgi(3, 4, 2, 1, 111);
  wrap_atlases(r, 3, 112);
  loader::SampleOptions off;
  off.use_visibility = false;
  check(r, FloatPrecision::Full, off, "3x4x2 L1 k=3 no visibility");
  loader::SampleOptions hard;
  hard.smooth_backface = 0.f;
  hard.normal_bias_cells = 0.f;  // the 1 mm bias alone
  check(r, FloatPrecision::Full, hard, "3x4x2 L1 k=3 hard back faces");
  loader::SampleOptions half;
  half.smooth_backface = 0.5f;
  half.normal_bias = 0.4f;  // larger than 0.3 cells
  half.variance_floor = 0.02f;
  check(r, FloatPrecision::Half, half, "3x4x2 L1 k=3 blended, large bias");
  loader::SampleOptions no_fade, wide_fade;  // DDGI's weights; a fade over the whole back half
  no_fade.behind_fade = 0.f;
  check(r, FloatPrecision::Full, no_fade, "3x4x2 L1 k=3 no behind fade");
  wide_fade.behind_fade = 1.f;
  check(r, FloatPrecision::Full, wide_fade, "3x4x2 L1 k=3 wide behind fade");
}

TEST_F(GlslSampler, InactiveCellsOneProbeAxesAndNoDepth) {
  DdgiResult r = test::make_ddgi(4, 3, 3, 2, 121);
  wrap_atlases(r, 1, 122);     // one plane per band: the tallest wrap
  for (int z = 0; z < 2; ++z)  // the cells of the corner x, y, z in [0, 1] have no active probe
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) r.states[size_t(x + 4 * (y + 3 * z))] = ProbeState::Inactive;
  r.states[5] = ProbeState::SkyOnly;
  const Agreement a = check(r, FloatPrecision::Full, {}, "4x3x3 L2 k=1 inactive corner");
  EXPECT_LT(a.lit, a.queries);                         // some queries found no active probe: zero on both sides
  DdgiResult flat = test::make_ddgi(5, 1, 4, 2, 123);  // one probe along Y
  check(flat, FloatPrecision::Half, {}, "5x1x4 L2 flat");
  DdgiResult line = test::make_ddgi(1, 1, 6, 2, 124);
  check(line, FloatPrecision::Full, {}, "1x1x6 L2 line");
  DdgiResult single = test::make_ddgi(1, 1, 1, 2, 125);
  check(single, FloatPrecision::Full, {}, "1x1x1 L2 single probe", 50);
  DdgiResult bare = test::make_ddgi(3, 3, 2, 2, 126, /*atlases=*/false);
  bare.offsets.clear();
  bare.states.clear();
  bare.stats.clear();
  const Agreement b = check(bare, FloatPrecision::Half, {}, "3x3x2 L2 no atlases, states, offsets");
  EXPECT_EQ(b.atlas_matters, 0u);  // no irradiance atlas: the SH either way
}

// A sparse volume (format 1.5; what a near-surface volume writes): two probes in three not stored,
// a wrapped grid layout re-laid in slot order, a sky-only probe among them.
TEST_F(GlslSampler, SparseVolume) {
  DdgiResult r = test::make_ddgi(5, 4, 3, 2, 131);
  wrap_atlases(r, 3, 132);
  for (size_t p = 0; p < r.states.size(); ++p) r.states[p] = p % 3 == 0 ? ProbeState::Active : ProbeState::Inactive;
  r.states[3] = ProbeState::SkyOnly;
  r.sparse = true;
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_bytes(r, FloatPrecision::Full, bytes);
  ASSERT_TRUE(file.ddgi_volumes()[0].sparse());
  EXPECT_EQ(file.ddgi_volumes()[0].stored_probes(), 20u);
  const Agreement a = check(r, FloatPrecision::Full, {}, "5x4x3 L2 sparse f32");
  EXPECT_GT(a.lit, a.queries / 4);
  EXPECT_GT(a.visibility_matters, a.queries / 8);
  check(r, FloatPrecision::Half, {}, "5x4x3 L2 sparse f16");
  check(r, FloatPrecision::SharedExponent, {}, "5x4x3 L2 sparse rgb9e5");
  for (size_t i = 0; i < r.irradiance_atlas.size(); i += 4) r.irradiance_atlas[i] *= 3000.f;  // sunlight: scaled
  std::vector<uint8_t> sunlit_bytes;
  const loader::BakeFile sunlit = open_bytes(r, FloatPrecision::SharedExponent, sunlit_bytes);
  EXPECT_GT(sunlit.ddgi_volumes()[0].desc().irradiance_scale, 1.f);
  check(r, FloatPrecision::SharedExponent, {}, "5x4x3 L2 sparse rgb9e5 scaled");
  loader::SampleOptions sh;
  sh.use_irradiance_atlas = false;
  check(r, FloatPrecision::Full, sh, "5x4x3 L2 sparse f32 SH");
}

// A real bake of the bundled Cornell box (CPU, 5x5x5 probes, 64 rays, relocation and
// classification on, the irradiance atlas written as by default): queries over the room, on its
// walls with normals facing in, and outside; through the atlas (the default) and the SH.
TEST_F(GlslSampler, BakedCornellBox) {
  Scene scene;
  ASSERT_TRUE(
      import_scene(std::string(GIBAKE_SOURCE_DIR) + "/samples/cornell/cornell.gltf", {}, Context{}, scene).is_ok());
  DdgiSettings s;
  s.rays = 64;
  s.bounces = 1;
  s.grid.counts = {5, 5, 5};
  DdgiResult r;
  DdgiReport rep;
  ASSERT_TRUE(bake_ddgi(scene, s, Context{}, r, rep).is_ok());
  std::printf("cornell bake: %d probes, %d active, %d inactive, %d relocated\n", rep.probes, rep.active, rep.inactive,
              rep.relocated);
  EXPECT_GT(rep.inactive, 0);  // the probes in the boxes and outside the room
  EXPECT_GT(rep.relocated, 0);
  std::vector<uint8_t> bytes;
  for (FloatPrecision precision : {FloatPrecision::Auto, FloatPrecision::Full}) {
    const loader::BakeFile file = open_bytes(r, precision, bytes);
    ASSERT_EQ(file.ddgi_volumes().size(), 1u);
    std::vector<Query> q = make_queries(file.ddgi_volumes()[0], 29, 400);
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> u(-0.98f, 0.98f);
    for (int i = 0; i < 100; ++i) {  // the walls, floor and ceiling, facing into the room
      q.push_back({{-1.f, 1.f + u(rng), u(rng)}, {1.f, 0.f, 0.f}});
      q.push_back({{1.f, 1.f + u(rng), u(rng)}, {-1.f, 0.f, 0.f}});
      q.push_back({{u(rng), 0.f, u(rng)}, {0.f, 1.f, 0.f}});
      q.push_back({{u(rng), 2.f, u(rng)}, {0.f, -1.f, 0.f}});
      q.push_back({{u(rng), 1.f + u(rng), -1.f}, {0.f, 0.f, 1.f}});
    }
    const std::string label = precision == FloatPrecision::Full ? "cornell 5^3 f32" : "cornell 5^3 auto";
    ASSERT_TRUE(file.ddgi_volumes()[0].has_irradiance()) << label << ": the bake wrote no irradiance atlas";
    const Agreement a = compare(*ctx_, file, {}, q, label);
    EXPECT_GT(a.lit, a.queries / 2);
    loader::SampleOptions off;
    off.use_visibility = false;
    EXPECT_GT(differing(file.ddgi_volumes()[0], q, {}, off), q.size() / 8) << "visibility must matter";
    compare(*ctx_, file, off, q, label + " no visibility");
    loader::SampleOptions sh;
    sh.use_irradiance_atlas = false;
    const size_t atlas_matters = differing(file.ddgi_volumes()[0], q, {}, sh);
    std::printf("%-34s (CPU) atlas/SH changes %zu queries\n", label.c_str(), atlas_matters);
    EXPECT_GT(atlas_matters, q.size() / 2) << "the default must read the irradiance atlas";
    compare(*ctx_, file, sh, q, label + " SH");
  }
  // The same bake with the file's depth tiles coarsened (--depth-tile 8 and 4): the GLSL sampler
  // takes the tile size from the volume record as the CPU's does.
  for (int tile : {8, 4}) {
    DdgiResult coarse = r;
    coarsen_depth_atlas(coarse, tile);
    const loader::BakeFile file = open_bytes(coarse, FloatPrecision::Auto, bytes);
    ASSERT_EQ(file.ddgi_volumes().size(), 1u);
    ASSERT_EQ(file.ddgi_volumes()[0].desc().depth_tile, uint32_t(tile));
    const std::vector<Query> q = make_queries(file.ddgi_volumes()[0], 37, 400);
    const Agreement a = compare(*ctx_, file, {}, q, "cornell 5^3 depth tiles " + std::to_string(tile));
    EXPECT_GT(a.lit, a.queries / 2);
  }
}

}  // namespace
}  // namespace gibake
