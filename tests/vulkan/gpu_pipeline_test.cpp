// Chunks in flight (vk::Recording, bake/vulkan/path_pipeline.h) on lavapipe. The answers are known
// without the pipeline: a recording's results equal the synchronous route's (Context::run and
// download) bit for bit, also with two recordings in flight that share the device buffers they
// overwrite; and a whole bake traced as many small chunks, three in flight, gives the same bytes as
// one chunk in flight at the default size (per probe nothing may change: rays are keyed by probe
// and ray, every reduction is per probe); the bake's notes confirm the chunks and how many were in
// flight. Tolerance: none, every value compared exactly.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/vulkan/path.h"
#include "bake/vulkan/raygen.h"
#include "kernels/ray_gen.h"
#include "tests/bake/scene_builders.h"
#include "tests/support/probe_grid.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

std::vector<gpu::GpuRayGenProbe> records(uint32_t first_probe, size_t count, uint64_t seed) {
  std::vector<gpu::GpuRayGenProbe> v;
  for (size_t i = 0; i < count; ++i)
    v.push_back(raygen_probe({float(i), 2.f * float(i), -1.f}, seed, first_probe + uint32_t(i), 3));
  return v;
}

// Two recordings share the probe table and the ray buffer: the second's upload must wait for the
// first's dispatch and download, or the first reads the second's probes.
TEST(VulkanRecording, TwoInFlightMatchTheSynchronousRoute) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  std::unique_ptr<GpuRayGen> gen;
  Status st = GpuRayGen::create(*vk, gen);
  ASSERT_TRUE(st) << st.message();
  const uint32_t n = 37;  // not a multiple of the workgroup
  const size_t probes = 5;
  const uint64_t seed = 0x123456789abcull;
  std::vector<float> fib(size_t(n) * 3);
  kernels::spherical_fibonacci_set(n, fib.data());
  ASSERT_TRUE(st = gen->set_fibonacci(fib.data(), n)) << st.message();
  ASSERT_TRUE(st = gen->reserve_probes(probes)) << st.message();
  vk::Buffer rays;
  const uint64_t bytes = probes * n * sizeof(gpu::GpuPathRay);
  ASSERT_TRUE(st = vk->create_buffer(bytes, rays, "rays")) << st.message();
  const auto a = records(0, probes, seed), b = records(1000, probes, seed);

  std::vector<gpu::GpuPathRay> sync_a(probes * n), sync_b(probes * n);
  ASSERT_TRUE(st = gen->set_probes(a)) << st.message();
  ASSERT_TRUE(st = vk->run({gen->dispatch(rays, 0, uint32_t(probes * n), seed)})) << st.message();
  ASSERT_TRUE(st = vk->download(rays, sync_a.data(), bytes)) << st.message();
  ASSERT_TRUE(st = gen->set_probes(b)) << st.message();
  ASSERT_TRUE(st = vk->run({gen->dispatch(rays, 0, uint32_t(probes * n), seed)})) << st.message();
  ASSERT_TRUE(st = vk->download(rays, sync_b.data(), bytes)) << st.message();
  ASSERT_NE(std::memcmp(sync_a.data(), sync_b.data(), bytes), 0);

  for (int round = 0; round < 3; ++round) {  // reused recordings: nothing of a round leaks into the next
    vk::Recording ra, rb;
    ASSERT_TRUE(st = gen->record_probes(a, ra)) << st.message();
    const size_t da = ra.dispatch(gen->dispatch(rays, 0, uint32_t(probes * n), seed));
    const size_t ia = ra.download(rays, bytes);
    ASSERT_TRUE(st = gen->record_probes(b, rb)) << st.message();
    rb.dispatch(gen->dispatch(rays, 0, uint32_t(probes * n), seed));
    const size_t ib = rb.download(rays, bytes);
    ASSERT_TRUE(st = vk->submit(ra)) << st.message();
    ASSERT_TRUE(st = vk->submit(rb)) << st.message();
    EXPECT_FALSE(vk->submit(ra));  // still in flight
    ASSERT_TRUE(st = vk->wait(rb)) << st.message();
    ASSERT_TRUE(st = vk->wait(ra)) << st.message();
    EXPECT_EQ(std::memcmp(ra.result(ia), sync_a.data(), bytes), 0) << "round " << round;
    EXPECT_EQ(std::memcmp(rb.result(ib), sync_b.data(), bytes), 0) << "round " << round;
    ASSERT_EQ(ra.dispatch_seconds().size(), 1u);
    EXPECT_GE(ra.dispatch_seconds()[da], 0.0);
    EXPECT_GE(ra.device_seconds(), 0.0);
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

// A lit room of 4x3x4 probes, baked on lavapipe with the pipeline's knobs.
// `pipeline` gets the bake's trace-pipeline note (chunks, most in flight, device and wall time).
Status bake_room(const DdgiSettings& base, uint32_t in_flight, uint64_t chunk_rays, DdgiResult& r,
                 std::string& pipeline) {
  Scene scene;
  test::add_box(scene, {0, 0, 0}, {4, 3, 4}, /*inward=*/true, test::add_material(scene, 0.6f));
  test::add_box(scene, {1.4f, 0, 1.4f}, {2.2f, 1.2f, 2.2f}, /*inward=*/false, test::add_material(scene, 0.4f));
  test::add_quad(scene, {1.6f, 2.99f, 1.6f}, {2.4f, 2.99f, 1.6f}, {2.4f, 2.99f, 2.4f}, {1.6f, 2.99f, 2.4f}, {0, -1, 0},
                 test::add_material(scene, 0.f, 40.f));
  DdgiSettings s = base;
  s.backend.backend = Backend::Vulkan;
  s.backend.vulkan_device = "lavapipe";
  s.backend.validation = true;
  s.backend.vulkan_in_flight = in_flight;
  s.backend.vulkan_chunk_rays = chunk_rays;
  DdgiReport rep;
  Context ctx;
  ctx.info = [&](const std::string& m) {
    if (m.find("vulkan: trace pipeline") != std::string::npos) pipeline = m;
  };
  return bake_ddgi(scene, s, ctx, r, rep);
}

void expect_same(const DdgiResult& a, const DdgiResult& b) {
  EXPECT_EQ(a.sh, b.sh);
  EXPECT_EQ(a.irradiance_atlas, b.irradiance_atlas);
  EXPECT_EQ(a.depth_atlas, b.depth_atlas);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.states, b.states);
  ASSERT_EQ(a.stats.size(), b.stats.size());
  for (size_t i = 0; i < a.stats.size(); ++i) {
    EXPECT_EQ(a.stats[i].rays, b.stats[i].rays) << "probe " << i;
    EXPECT_EQ(a.stats[i].relative_error, b.stats[i].relative_error) << "probe " << i;
    EXPECT_EQ(a.stats[i].backface_fraction, b.stats[i].backface_fraction) << "probe " << i;
  }
}

// One chunk in flight at the default size against 3-probe chunks (16 a batch), 3 in flight; the
// notes show that the knobs took effect.
void check_bake(const DdgiSettings& s, const std::string& one_note, const std::string& many_note) {
  std::string why;
  if (test::vulkan_missing(why)) GTEST_SKIP() << why;
  DdgiResult one, many;
  std::string note_one, note_many;
  Status st = bake_room(s, 1, 0, one, note_one);
  ASSERT_TRUE(st) << st.message();
  ASSERT_TRUE(st = bake_room(s, 3, uint64_t(s.rays) * 3, many, note_many)) << st.message();
  EXPECT_NE(note_one.find(one_note), std::string::npos) << note_one;
  EXPECT_NE(note_many.find(many_note), std::string::npos) << note_many;
  ASSERT_FALSE(one.sh.empty());
  expect_same(one, many);
}

DdgiSettings room_probes(uint32_t rays) {
  DdgiSettings s = test::probe_grid({0.5f, 0.5f, 0.5f}, {3.5f, 2.5f, 3.5f}, {4, 3, 4}, rays);
  s.seed = 7;
  return s;
}

TEST(VulkanPipeline, PathGatherSameBytesWithManyChunksInFlight) {
  check_bake(room_probes(64), " 1 chunk(s), up to 1 in flight", " 16 chunk(s), up to 3 in flight");
}

TEST(VulkanPipeline, ProbeGatherSameBytesWithManyChunksInFlight) {
  DdgiSettings s = room_probes(64);
  s.gather = Gather::Probes;
  s.bounces = kProbeGatherBounces;
  check_bake(s, " 1 chunk(s), up to 1 in flight", " 16 chunk(s), up to 3 in flight");
}

TEST(VulkanPipeline, TargetErrorSameBytesWithManyChunksInFlight) {
  DdgiSettings s = room_probes(32);
  s.target_error = 0.05f;
  s.max_rays = 256;
  // Later batches hold only the probes still above the target: more chunks, counted over batches.
  check_bake(s, " up to 1 in flight", " up to 3 in flight");
}

}  // namespace
}  // namespace gibake
