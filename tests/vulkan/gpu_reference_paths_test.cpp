// The reconstruction check's reference paths on the device (path.comp mode 2, bake/vulkan/
// reference_paths.h) against the CPU's trace_radiance: the same patches and points, sums within
// float rounding, and the white furnace's analytic answer; the sums kernel on known briefs. Also the
// path tracer's chunk buffers, which those tests' tracer makes: per-ray outputs only where read.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "bake/preview/reconstruction_check.h"
#include "bake/scene/emitters.h"
#include "bake/scene/lights.h"
#include "bake/vulkan/path.h"
#include "bake/vulkan/pipelines.h"
#include "bake/vulkan/reference_paths.h"
#include "kernels/ray_gen.h"
#include "tests/bake/scene_builders.h"
#include "tests/vulkan/gpu_test_scenes.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

// A session on the test device holding a path tracer over `scene`, as a DDGI trace leaves it.
struct DeviceScene {
  std::shared_ptr<GpuSession> session = std::make_shared<GpuSession>();
  std::unique_ptr<PreparedScene> prepared;
  TextureLod lod;
  std::unique_ptr<EmitterTable> emitters;
  GpuPathSetup setup;  // the reference tracer's
};

// False (the test skipped) when no device opens.
bool open_scene(const Scene& scene, const std::vector<kernels::ShadeLight>& lights, const Sky& sky, DeviceScene& out) {
  std::unique_ptr<vk::Context> vk;
  if (!test::open_test_device(vk).empty()) return false;
  out.session->vk = std::move(vk);
  EXPECT_TRUE(PreparedScene::create(scene, Context{}, out.prepared));
  out.lod = TextureLod(scene, Context{});
  out.emitters = std::make_unique<EmitterTable>(scene);
  EXPECT_TRUE(build_gpu_scene(scene, {}, Context{}, out.session->scene));
  EXPECT_TRUE(GpuTracer::create(*out.session->vk, out.session->scene, out.session->tracer, 1u << 16));
  GpuPathSetup gs;
  gs.scene = &scene;
  gs.lod = &out.lod;
  gs.emitters = out.emitters.get();
  gs.lights = &lights;
  gs.sky = &sky;
  gs.bounces = 1;  // the bake's path settings: the check brings its own
  gs.cone_spread = 0.5f;
  out.setup = gs;
  // A small batch, so that the check's paths take several.
  EXPECT_TRUE(GpuPathTracer::create(*out.session->tracer, gs, out.session->reference_tracer, 4096));
  return true;
}

// The reference from `probes` traced on the CPU and on the device.
void trace_both(DeviceScene& d, const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                const std::vector<kernels::float3>& probes, ReconstructionSettings rs, ReconstructionReference& cpu,
                ReconstructionReference& gpu) {
  ASSERT_TRUE(trace_reconstruction_reference(*d.prepared, d.lod, lights, sky, probes, rs, Context{}, cpu));
  std::unique_ptr<ReferencePathDevice> device = make_gpu_reference_paths(d.session, /*cpu_device_too=*/true);
  ASSERT_NE(device, nullptr);
  ASSERT_TRUE(device->lights_match(lights, sky));
  rs.device = device.get();
  const Status traced = trace_reconstruction_reference(*d.prepared, d.lod, lights, sky, probes, rs, Context{}, gpu);
  ASSERT_TRUE(traced) << traced.message();
  EXPECT_FALSE(gpu.device.empty());
  EXPECT_TRUE(cpu.device.empty());
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(d.session->vk);
}

// Same patches, same points bit for bit (picked on the host), sums within `tolerance` (relative).
void expect_same_reference(const ReconstructionReference& cpu, const ReconstructionReference& gpu, double tolerance) {
  ASSERT_EQ(cpu.patches.size(), gpu.patches.size());
  uint64_t rays_cpu = 0, rays_gpu = 0;
  size_t compared = 0;
  double worst = 0.0;
  for (size_t i = 0; i < cpu.patches.size(); ++i) {
    const ReconstructionPatch &a = cpu.patches[i], &b = gpu.patches[i];
    ASSERT_EQ(a.points, b.points) << i;
    EXPECT_EQ(a.position, b.position) << i;
    ASSERT_EQ(cpu.points[i].size(), gpu.points[i].size());
    for (size_t j = 0; j < cpu.points[i].size(); ++j) EXPECT_EQ(cpu.points[i][j].direct.x, gpu.points[i][j].direct.x);
    if (a.points == 0) continue;
    ++compared;
    worst = std::max(worst, std::fabs(double(b.reference) / a.reference - 1.0));
    EXPECT_NEAR(b.reference, a.reference, tolerance * a.reference + 1e-6) << i;
    EXPECT_NEAR(b.indirect_reference, a.indirect_reference, tolerance * a.indirect_reference + 1e-6) << i;
    rays_cpu += cpu.rays[i];
    rays_gpu += gpu.rays[i];
  }
  std::printf("%zu patches compared, largest relative difference %.2e, rays %llu (cpu) %llu (device)\n", compared,
              worst, static_cast<unsigned long long>(rays_cpu), static_cast<unsigned long long>(rays_gpu));
  EXPECT_GT(compared, cpu.patches.size() / 2);
  // The same paths: their rays counted alike but where rounding ends one differently.
  EXPECT_NEAR(double(rays_gpu), double(rays_cpu), 1e-3 * double(rays_cpu));
}

TEST(GpuReferencePaths, FurnaceMatchesTheCpuAndTheAnswer) {
  constexpr float kRho = 0.7f, kLe = 1.f;
  constexpr int kBounces = 3;
  Scene scene;
  test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, kRho, kLe));
  const std::vector<kernels::ShadeLight> lights;
  const Sky sky;
  DeviceScene d;
  if (!open_scene(scene, lights, sky, d)) GTEST_SKIP() << "no Vulkan device";
  ReconstructionSettings rs;
  rs.patches = 12;
  rs.rays = 64;
  rs.bounces = kBounces;
  rs.roulette_depth = 16;
  const std::vector<kernels::float3> probes = {{0.f, 0.f, 0.f}, {0.4f, -0.3f, 0.2f}};
  ReconstructionReference cpu, gpu;
  trace_both(d, lights, sky, probes, rs, cpu, gpu);
  // Float rounding only: 1e-4, far above float rounding's few 1e-7.
  expect_same_reference(cpu, gpu, 1e-4);
  // The furnace: every point's shaded luminance Le + rho E / pi = Le sum_{k <= N+2} rho^k, within
  // the 2% of the CPU's furnace test (MIS noise of 16 x 64 paths a patch).
  double g = 0.0;
  for (int k = 0; k <= kBounces + 1; ++k) g += std::pow(kRho, k);
  const double expected = kLe * (1.0 + kRho * g);
  for (const ReconstructionPatch& p : gpu.patches)
    if (p.points > 0) {
      EXPECT_NEAR(p.reference / p.points, expected, 0.02 * expected);
    }
}

// Sun, sky, single-sided back faces, several device batches (4,096 paths each).
TEST(GpuReferencePaths, SunAndSkyMatchTheCpu) {
  const Scene scene = test::floor_and_wall();
  SunLight sun;
  sun.direction = {0.3f, -1.f, 0.2f};
  sun.lux = 1000.f;
  const std::vector<kernels::ShadeLight> lights = shade_lights(scene, {sun});
  Sky sky;
  sky.constant = {0.2f, 0.3f, 0.5f};
  DeviceScene d;
  if (!open_scene(scene, lights, sky, d)) GTEST_SKIP() << "no Vulkan device";
  ReconstructionSettings rs;
  rs.patches = 16;
  rs.rays = 64;
  const std::vector<kernels::float3> probes = {{0.f, 1.f, 0.f}, {0.5f, 0.5f, -0.5f}, {-0.5f, 2.f, 0.5f}};
  ReconstructionReference cpu, gpu;
  trace_both(d, lights, sky, probes, rs, cpu, gpu);
  expect_same_reference(cpu, gpu, 1e-4);
  // Lighting the device was not set up with is traced on the CPU.
  std::unique_ptr<ReferencePathDevice> device = make_gpu_reference_paths(d.session, true);
  Sky other = sky;
  other.constant.x = 0.25f;
  EXPECT_FALSE(device->lights_match(lights, other));
  EXPECT_FALSE(device->lights_match({}, sky));
  rs.device = device.get();
  ReconstructionReference fallback;
  ASSERT_TRUE(trace_reconstruction_reference(*d.prepared, d.lod, lights, other, probes, rs, Context{}, fallback));
  EXPECT_TRUE(fallback.device.empty());
}

// reference_sums.comp alone, made ahead by the context's own thread (create_pipelines_beside):
// each point's briefs summed in path order, paths below the surface counted in their half only.
TEST(GpuReferencePaths, SumsKernelMadeAheadSumsInPathOrder) {
  std::unique_ptr<vk::Context> vk;
  GIBAKE_OPEN_VULKAN_OR_SKIP(vk);
  vk->create_pipelines_beside({pipelines::reference_sums(), pipelines::raygen()});
  vk::Pipeline sums;
  ASSERT_TRUE(vk->create_pipeline(pipelines::reference_sums(), sums));
  EXPECT_EQ(vk->pipelines_taken_ahead(), 1u);
  // Two points of three paths: (radiance, t), (shadow, bounce, half, traced). The second path is
  // below its surface: only its light sample (one shadow ray) counts.
  const std::vector<gpu::GpuPathBrief> briefs = {
      {{1.f, 2.f, 3.f, 1.f}, {2u, 1u, 0u, 1u}},  {{0.25f, 0.5f, 0.f, -1.f}, {1u, 0u, 1u, 0u}},
      {{0.5f, 0.f, 0.f, 2.f}, {1u, 3u, 1u, 1u}}, {{0.f, 1.f, 0.f, 1.f}, {4u, 0u, 0u, 1u}},
      {{0.f, 0.f, 2.f, 1.f}, {0u, 2u, 1u, 1u}},  {{1.f, 1.f, 1.f, -1.f}, {1u, 1u, 0u, 1u}}};
  vk::Buffer in, out;
  ASSERT_TRUE(vk->create_buffer(briefs.size() * sizeof(gpu::GpuPathBrief), in, "briefs"));
  ASSERT_TRUE(vk->create_buffer(2 * sizeof(gpu::GpuReferenceSums), out, "sums"));
  ASSERT_TRUE(vk->upload(in, briefs.data(), briefs.size() * sizeof(gpu::GpuPathBrief)));
  vk::Dispatch d;
  d.pipeline = &sums;
  d.buffers = {&in, &out};
  d.push = vk::push_bytes(gpu::ReferenceSumsPush{{2u, 3u, 0u, GPU_RAY_WINDOW}});
  ASSERT_TRUE(vk->run({d}));
  gpu::GpuReferenceSums got[2];
  ASSERT_TRUE(vk->download(out, got, sizeof(got)));
  const auto lum = [](float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; };
  EXPECT_FLOAT_EQ(got[0].sum.x, 1.75f);  // the untraced path's light sample counts
  EXPECT_FLOAT_EQ(got[0].sum.y, 2.5f);
  EXPECT_FLOAT_EQ(got[0].sum.z, 3.f);
  EXPECT_FLOAT_EQ(got[0].sum.w, lum(1.f, 2.f, 3.f));
  EXPECT_FLOAT_EQ(got[0].half_lum.x, lum(0.25f, 0.5f, 0.f) + lum(0.5f, 0.f, 0.f));
  EXPECT_EQ(got[0].counts.x, 1u);  // half 0: path 0
  EXPECT_EQ(got[0].counts.y, 2u);  // half 1: paths 1 (untraced) and 2
  EXPECT_EQ(got[0].counts.z, 4u);  // shadow rays of every path
  EXPECT_EQ(got[0].counts.w, 4u);
  EXPECT_EQ(got[0].traced.x, 2u);  // the paths' first rays: not the untraced one's
  EXPECT_FLOAT_EQ(got[1].sum.x, 1.f);
  EXPECT_FLOAT_EQ(got[1].sum.y, 2.f);
  EXPECT_FLOAT_EQ(got[1].sum.z, 3.f);
  EXPECT_EQ(got[1].traced.x, 3u);
  EXPECT_EQ(got[1].counts.x, 2u);
  EXPECT_EQ(got[1].counts.z, 5u);
  // In windows of two paths, then one: each continues the sums the one before stored, to the bit.
  vk::Dispatch w0 = d, w1 = d;
  w0.push = vk::push_bytes(gpu::ReferenceSumsPush{{2u, 3u, 0u, 2u}});
  w1.push = vk::push_bytes(gpu::ReferenceSumsPush{{2u, 3u, 2u, 2u}});
  ASSERT_TRUE(vk->fill_zero(out));
  ASSERT_TRUE(vk->run({w0, w1}));
  gpu::GpuReferenceSums windowed[2];
  ASSERT_TRUE(vk->download(out, windowed, sizeof(windowed)));
  EXPECT_EQ(std::memcmp(windowed, got, sizeof(got)), 0);
  vk::Pipeline again;  // the one made ahead is taken: a second is made anew
  ASSERT_TRUE(vk->create_pipeline(pipelines::reference_sums(), again));
  EXPECT_EQ(vk->pipelines_taken_ahead(), 1u);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(vk);
}

}  // namespace
}  // namespace gibake

namespace gibake {
namespace {

// A grey box (albedo 0.5, no lights) open on the test device: the tracer's own tests' scene.
struct GreyBox {
  Scene scene;
  const std::vector<kernels::ShadeLight> lights;
  const Sky sky;
  DeviceScene d;
  bool open() {
    test::add_box(scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, test::add_material(scene, 0.5f, 0.f));
    return open_scene(scene, lights, sky, d);
  }
};

// The trace's chunk buffers (bake/vulkan/path_pipeline.cpp): the brief route, which never writes a
// GpuPathOut, makes rays and briefs only; a full-output route adds a GpuPathOut for every ray of a
// batch, and nothing is made again for a route the buffers already serve.
TEST(GpuPathTracerBuffers, BriefRouteMakesNoPerRayOutputs) {
  GreyBox box;
  if (!box.open()) GTEST_SKIP() << "no Vulkan device";
  DeviceScene& d = box.d;
  GpuPathTracer& tracer = *d.session->reference_tracer;
  ASSERT_FALSE(tracer.probe_lights());          // no emitter sample per ray in this scene
  constexpr uint32_t kRays = 64, kProbes = 16;  // 1,024 rays: one batch of the tracer's 4,096
  std::vector<float> fib(kRays * 3);
  kernels::spherical_fibonacci_set(kRays, fib.data());
  ASSERT_TRUE(tracer.set_fibonacci(fib.data(), kRays));
  const uint64_t before = tracer.device_bytes();
  const uint64_t rays = uint64_t(kRays) * kProbes;
  ASSERT_TRUE(tracer.reserve_chunks(kProbes, /*full_outputs=*/false));
  EXPECT_EQ(tracer.device_bytes() - before, rays * (sizeof(gpu::GpuPathRay) + sizeof(gpu::GpuPathBrief)));
  ASSERT_TRUE(tracer.reserve_chunks(kProbes, /*full_outputs=*/true));
  EXPECT_EQ(tracer.device_bytes() - before,
            rays * (sizeof(gpu::GpuPathRay) + sizeof(gpu::GpuPathBrief) + sizeof(gpu::GpuPathOut)));
  const uint64_t full = tracer.device_bytes();
  ASSERT_TRUE(tracer.reserve_chunks(kProbes, /*full_outputs=*/false));
  ASSERT_TRUE(tracer.reserve_chunks(kProbes / 2, /*full_outputs=*/true));
  EXPECT_EQ(tracer.device_bytes(), full);
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(d.session->vk);
}

// A later volume's trace takes the tracer an earlier one made (bake/vulkan/ddgi_device.cpp
// begin_trace) only when create() would make the same bytes: the same setup serves, another
// bounce count, cone spread or light does not.
TEST(GpuPathTracerBuffers, ServesOnlyTheSetupItWasMadeFor) {
  GreyBox box;
  if (!box.open()) GTEST_SKIP() << "no Vulkan device";
  DeviceScene& d = box.d;
  const GpuPathTracer& tracer = *d.session->reference_tracer;
  EXPECT_TRUE(tracer.serves(d.setup));
  GpuPathSetup other = d.setup;
  other.bounces = d.setup.bounces + 1;
  EXPECT_FALSE(tracer.serves(other));
  other = d.setup;
  other.cone_spread = d.setup.cone_spread * 2.f;
  EXPECT_FALSE(tracer.serves(other));
  other = d.setup;
  other.probe_feedback = !d.setup.probe_feedback;
  EXPECT_FALSE(tracer.serves(other));
  const std::vector<kernels::ShadeLight> sun = {kernels::ShadeLight{}};
  other = d.setup;
  other.lights = &sun;
  EXPECT_FALSE(tracer.serves(other));
  const std::vector<kernels::ShadeLight> no_lights;  // the same lights held elsewhere
  other = d.setup;
  other.lights = &no_lights;
  EXPECT_TRUE(tracer.serves(other));
}

}  // namespace
}  // namespace gibake
