// The Vulkan context on lavapipe: device listing, buffer round trips, a dispatch, limits.
#include <gtest/gtest.h>

#include <fstream>
#include <numeric>
#include <thread>

#include "bake/vulkan/traverse.h"
#include "tests/vulkan/gpu_test_scenes.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

TEST(VulkanContext, ListsDevicesWithNamesAndTypes) {
  std::vector<vk::DeviceInfo> devices;
  ASSERT_TRUE(vk::list_devices(devices));
  if (devices.empty()) GTEST_SKIP() << "the Vulkan loader found no device (install mesa-vulkan-drivers)";
  for (size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, i);
    EXPECT_FALSE(devices[i].name.empty());
    EXPECT_FALSE(devices[i].driver.empty());
    EXPECT_NE(devices[i].type, "");
  }
}

TEST(VulkanContext, BufferRoundTripAndOffsets) {
  std::unique_ptr<vk::Context> ctx;
  GIBAKE_OPEN_VULKAN_OR_SKIP(ctx);
  std::vector<uint32_t> data(100000);
  std::iota(data.begin(), data.end(), 7u);
  vk::Buffer buf;
  ASSERT_TRUE(ctx->create_buffer(data.size() * 4, buf, "test"));
  EXPECT_EQ(buf.size(), data.size() * 4);
  ASSERT_TRUE(ctx->upload(buf, data.data(), data.size() * 4));
  std::vector<uint32_t> back(data.size(), 0);
  ASSERT_TRUE(ctx->download(buf, back.data(), back.size() * 4));
  EXPECT_EQ(back, data);
  // A part written at an offset and read back at another.
  const uint32_t part[3] = {1u, 2u, 3u};
  ASSERT_TRUE(ctx->upload(buf, part, sizeof(part), 400));
  uint32_t got[4] = {};
  ASSERT_TRUE(ctx->download(buf, got, sizeof(got), 396));
  EXPECT_EQ(got[0], data[99]);
  EXPECT_EQ(got[1], 1u);
  EXPECT_EQ(got[3], 3u);
  ASSERT_TRUE(ctx->fill_zero(buf));
  ASSERT_TRUE(ctx->download(buf, got, sizeof(got), 396));
  EXPECT_EQ(got[1], 0u);
  // Outside the buffer: an error, not a crash.
  EXPECT_FALSE(ctx->upload(buf, part, sizeof(part), buf.size() - 4));
  EXPECT_FALSE(ctx->download(buf, got, sizeof(got), buf.size()));
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx);
}

// The bake's set-up uploads the BVH and the texture pool from two threads at once: the shared
// staging buffer and command buffer must not mix them (without the context's lock, one thread's
// copy reads the other's bytes from staging).
TEST(VulkanContext, UploadsFromTwoThreadsAtOnceKeepTheirBytes) {
  std::unique_ptr<vk::Context> ctx;
  GIBAKE_OPEN_VULKAN_OR_SKIP(ctx);
  const size_t n = 1 << 18;  // 1 MiB a buffer, several staging rounds each over the loop
  std::vector<uint32_t> a(n), b(n);
  std::iota(a.begin(), a.end(), 1u);
  std::iota(b.begin(), b.end(), 0x80000000u);
  vk::Buffer ba, bb;
  ASSERT_TRUE(ctx->create_buffer(n * 4, ba, "a"));
  ASSERT_TRUE(ctx->create_buffer(n * 4, bb, "b"));
  for (int round = 0; round < 8; ++round) {
    Status sa = Status::ok(), sb = Status::ok();
    std::thread other([&] {
      for (size_t off = 0; off < n && sb; off += n / 16) sb = ctx->upload(bb, b.data() + off, n / 16 * 4, off * 4);
    });
    for (size_t off = 0; off < n && sa; off += n / 16) sa = ctx->upload(ba, a.data() + off, n / 16 * 4, off * 4);
    other.join();
    ASSERT_TRUE(sa) << sa.message();
    ASSERT_TRUE(sb) << sb.message();
    std::vector<uint32_t> back_a(n), back_b(n);
    ASSERT_TRUE(ctx->download(ba, back_a.data(), n * 4));
    ASSERT_TRUE(ctx->download(bb, back_b.data(), n * 4));
    ASSERT_EQ(back_a, a) << "round " << round;
    ASSERT_EQ(back_b, b) << "round " << round;
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx);
}

// Small buffers are pieces of shared blocks (kernels/vulkan/memory_pool.h): each keeps its own
// bytes, a freed piece is reused without a new allocation, and a large buffer has its own memory.
TEST(VulkanContext, SmallBuffersShareBlocksAndKeepTheirBytes) {
  std::unique_ptr<vk::Context> ctx;
  GIBAKE_OPEN_VULKAN_OR_SKIP(ctx);
  constexpr size_t kBuffers = 40;
  const auto words = [](size_t i) { return size_t(250) + i * 1733; };  // 1,000 bytes to 270 KiB, odd sizes
  const auto pattern = [&](size_t i, uint32_t round) {
    std::vector<uint32_t> v(words(i));
    std::iota(v.begin(), v.end(), uint32_t(i) << 24 | round << 20);
    return v;
  };
  std::vector<vk::Buffer> buffers(kBuffers);
  const auto make = [&](size_t i, uint32_t round) -> Status {
    const std::vector<uint32_t> v = pattern(i, round);
    if (i % 2) return ctx->create_filled_buffer(v.data(), v.size() * 4, buffers[i], "filled");
    GIBAKE_TRY(ctx->create_buffer(v.size() * 4, buffers[i], "staged"));
    return ctx->upload(buffers[i], v.data(), v.size() * 4);
  };
  const auto check_all = [&](const std::vector<uint32_t>& rounds) {
    for (size_t i = 0; i < kBuffers; ++i) {
      std::vector<uint32_t> back(words(i));
      ASSERT_TRUE(ctx->download(buffers[i], back.data(), back.size() * 4));
      ASSERT_EQ(back, pattern(i, rounds[i])) << "buffer " << i;
    }
  };
  {  // the context's own staging buffers made first, so that the counts below are the test's
    ASSERT_TRUE(make(0, 0));
    std::vector<uint32_t> back(words(0));
    ASSERT_TRUE(ctx->download(buffers[0], back.data(), back.size() * 4));
    buffers[0] = vk::Buffer();
  }
  const vk::MemoryStats before = ctx->memory_stats();
  for (size_t i = 0; i < kBuffers; ++i) ASSERT_TRUE(make(i, 0));
  std::vector<uint32_t> rounds(kBuffers, 0);
  check_all(rounds);
  const vk::MemoryStats made = ctx->memory_stats();
  EXPECT_GE(made.pieces, before.pieces + kBuffers);
  EXPECT_LE(made.allocations - before.allocations, 8u) << "40 small buffers, one allocation each?";
  // Every other buffer freed and made again, with other bytes: into the freed pieces.
  for (size_t i = 0; i < kBuffers; i += 2) buffers[i] = vk::Buffer();
  for (size_t i = 0; i < kBuffers; i += 2) {
    ASSERT_TRUE(make(i, 1));
    rounds[i] = 1;
  }
  check_all(rounds);
  EXPECT_EQ(ctx->memory_stats().allocations, made.allocations);
  // Larger than half of any block: memory of its own, freed with it.
  vk::Buffer large;
  ASSERT_TRUE(ctx->create_buffer(uint64_t(40) << 20, large, "large"));
  EXPECT_EQ(ctx->memory_stats().dedicated, made.dedicated + 1);
  large = vk::Buffer();
  EXPECT_EQ(ctx->memory_stats().dedicated, made.dedicated);
  buffers.clear();
  EXPECT_EQ(ctx->memory_stats().pieces, before.pieces);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx);
}

TEST(VulkanContext, ValidationLayerOnWhereInstalled) {
  std::unique_ptr<vk::Context> ctx;
  GIBAKE_OPEN_VULKAN_OR_SKIP(ctx);
  std::ifstream layer("/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json");
  if (!layer) GTEST_SKIP() << "vulkan-validationlayers is not installed";
  EXPECT_TRUE(ctx->validation_enabled());
}

TEST(VulkanContext, OversizedBufferNamesTheSize) {
  std::unique_ptr<vk::Context> ctx;
  GIBAKE_OPEN_VULKAN_OR_SKIP(ctx);
  vk::Buffer buf;
  const uint64_t huge = ctx->max_buffer_bytes() + 1;
  const Status st = ctx->create_buffer(huge, buf, "probe rays");
  EXPECT_EQ(st.code(), ExitCode::RuntimeFailure);
  EXPECT_NE(st.message().find(std::to_string(huge)), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("probe rays"), std::string::npos) << st.message();
  // The limit it ran into, by name.
  const bool named = st.message().find("(maxStorageBufferRange)") != std::string::npos ||
                     st.message().find("(maxMemoryAllocationSize)") != std::string::npos ||
                     st.message().find("(its device memory)") != std::string::npos;
  EXPECT_TRUE(named) << st.message();
}

// A grid past the device's maxComputeWorkGroupCount fails naming the limit; a flat grid of as many
// groups folds into rows and traces every ray (here under a test limit of 8 groups in x).
TEST(VulkanContext, GridsKeepToTheWorkgroupCount) {
  std::unique_ptr<vk::Context> ctx;
  const std::string why = test::open_test_device(ctx, 8);
  if (!why.empty()) GTEST_SKIP() << why;
  EXPECT_EQ(ctx->limits().group_count[0], 8u);
  // The floor at y = 0 under rays from y = 1 + i / n: hit distance 1 + i / n tells each ray's lane.
  const Scene scene = test::floor_and_wall();
  test::Tracers t;
  const uint32_t n = 64 * 50;  // 50 groups: 7 rows of 8 (the last one part empty)
  ASSERT_TRUE(test::make_tracers(*ctx, scene, t, n));
  GpuTracer* tracer = t.gpu.get();
  std::vector<gpu::GpuRay> rays(n);
  for (uint32_t i = 0; i < n; ++i) rays[i] = {{0.f, 1.f + float(i) / n, 0.f, 0.f}, {0.f, -1.f, 0.f, 1e30f}};
  std::vector<gpu::GpuHit> hits;
  ASSERT_TRUE(tracer->intersect(rays, hits));
  for (uint32_t i = 0; i < n; ++i) ASSERT_NEAR(hits[i].t_tri_uv.x, 1.f + float(i) / n, 1e-5f) << i;
  vk::Buffer a, b;
  ASSERT_TRUE(ctx->create_buffer(n * sizeof(gpu::GpuRay), a, "rays"));
  ASSERT_TRUE(ctx->create_buffer(n * sizeof(gpu::GpuHit), b, "hits"));
  vk::Dispatch d = tracer->closest_hits(a, b, n);
  d.flat_groups = 0;
  d.groups[0] = 9;  // one past the limit
  Status st = ctx->run({d});
  EXPECT_EQ(st.code(), ExitCode::RuntimeFailure);
  EXPECT_NE(st.message().find("(maxComputeWorkGroupCount)"), std::string::npos) << st.message();
  d.flat_groups = uint64_t(8) * ctx->limits().group_count[1] + 1;  // more rows than y allows
  st = ctx->run({d});
  EXPECT_NE(st.message().find("(maxComputeWorkGroupCount)"), std::string::npos) << st.message();
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx);
}

TEST(VulkanContext, EmptySceneTracesMissesWithTimestamps) {
  std::unique_ptr<vk::Context> ctx;
  GIBAKE_OPEN_VULKAN_OR_SKIP(ctx);
  GpuSceneData empty;
  empty.materials.push_back({});
  std::unique_ptr<GpuTracer> tracer;
  ASSERT_TRUE(GpuTracer::create(*ctx, empty, tracer, 256));
  std::vector<gpu::GpuRay> rays(1000, gpu::GpuRay{{0.f, 0.f, 0.f, 0.f}, {0.f, 1.f, 0.f, 1e30f}});
  std::vector<gpu::GpuHit> hits;
  double seconds = -1.0;
  ASSERT_TRUE(tracer->intersect(rays, hits, &seconds));  // 4 batches of 256 rays
  ASSERT_EQ(hits.size(), rays.size());
  for (const auto& h : hits) EXPECT_LT(h.t_tri_uv.x, 0.f);
  EXPECT_GE(seconds, 0.0);
  std::vector<uint32_t> blocked;
  ASSERT_TRUE(tracer->occluded(rays, blocked));
  for (uint32_t b : blocked) EXPECT_EQ(b, 0u);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(ctx);
}

}  // namespace
}  // namespace gibake
