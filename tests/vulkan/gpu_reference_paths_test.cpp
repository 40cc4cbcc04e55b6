// The reconstruction check's reference paths on the device (path.comp mode 2, bake/vulkan/
// reference_paths.h) against the CPU's trace_radiance: the same patches and points, sums within
// float rounding, and the white furnace's analytic answer; the surface fit's paths also ended in a
// probe field there (path_probe_field.comp) against the CPU's; the sums kernel on known briefs. Also the
// path tracer's chunk buffers, which those tests' tracer makes: per-ray outputs only where read.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "bake/preview/reconstruction_check.h"
#include "bake/scene/emitters.h"
#include "bake/scene/lights.h"
#include "bake/trace/probe_field_cache.h"
#include "bake/vulkan/path.h"
#include "bake/vulkan/pipelines.h"
#include "bake/vulkan/reference_paths.h"
#include "kernels/ray_gen.h"
#include "tests/bake/scene_builders.h"
#include "tests/loader/multi_volume.h"
#include "tests/loader/synthetic.h"
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
  // A second pass for nearly every patch, at several path counts (the device traces each count in
  // its own traces), within one budget on both sides (by default a device's is the larger).
  rs.target_noise = 0.002f;
  rs.ray_budget = 4 * rs.rays;
  ASSERT_TRUE(trace_reconstruction_reference(*d.prepared, d.lod, lights, sky, probes, rs, Context{}, cpu));
  std::unique_ptr<ReferencePathDevice> device = make_gpu_reference_paths(d.session, /*cpu_device_too=*/true);
  ASSERT_NE(device, nullptr);
  ASSERT_TRUE(device->lights_match(lights, sky));
  rs.device = device.get();
  const Status traced = trace_reconstruction_reference(*d.prepared, d.lod, lights, sky, probes, rs, Context{}, gpu);
  ASSERT_TRUE(traced) << traced.message();
  EXPECT_FALSE(gpu.device.empty());
  EXPECT_TRUE(cpu.device.empty());
  EXPECT_GT(cpu.retraced, 0u);
  EXPECT_EQ(gpu.retraced, cpu.retraced);
  EXPECT_EQ(gpu.retraced_rays, cpu.retraced_rays);
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

// The floor and wall under a 1,000 lux sun and a blue sky (the settings JSON of `kSunlitSettings`).
struct SunlitFloorAndWall {
  Scene scene = test::floor_and_wall();
  std::vector<kernels::ShadeLight> lights;
  Sky sky;
  SunlitFloorAndWall() {
    SunLight sun;
    sun.direction = {0.3f, -1.f, 0.2f};
    sun.lux = 1000.f;
    lights = shade_lights(scene, {sun});
    sky.constant = {0.2f, 0.3f, 0.5f};
  }
};
const char* const kSunlitSettings =
    R"({"suns":[{"direction":[0.3,-1,0.2],"lux":1000,"color":[1,1,1]}],"sky":[0.2,0.3,0.5]})";

// Sun, sky, single-sided back faces, several device batches (4,096 paths each).
TEST(GpuReferencePaths, SunAndSkyMatchTheCpu) {
  const SunlitFloorAndWall lit;
  DeviceScene d;
  if (!open_scene(lit.scene, lit.lights, lit.sky, d)) GTEST_SKIP() << "no Vulkan device";
  ReconstructionSettings rs;
  rs.patches = 16;
  rs.rays = 64;
  const std::vector<kernels::float3> probes = {{0.f, 1.f, 0.f}, {0.5f, 0.5f, -0.5f}, {-0.5f, 2.f, 0.5f}};
  ReconstructionReference cpu, gpu;
  trace_both(d, lit.lights, lit.sky, probes, rs, cpu, gpu);
  expect_same_reference(cpu, gpu, 1e-4);
  // Lighting the device was not set up with is traced on the CPU.
  std::unique_ptr<ReferencePathDevice> device = make_gpu_reference_paths(d.session, true);
  Sky other = lit.sky;
  other.constant.x = 0.25f;
  EXPECT_FALSE(device->lights_match(lit.lights, other));
  EXPECT_FALSE(device->lights_match({}, lit.sky));
  rs.device = device.get();
  ReconstructionReference fallback;
  ASSERT_TRUE(trace_reconstruction_reference(*d.prepared, d.lod, lit.lights, other, probes, rs, Context{}, fallback));
  EXPECT_TRUE(fallback.device.empty());
}

// Forwards to the device and counts what it was asked: whether the paths were ended there.
class CountingDevice final : public ReferencePathDevice {
 public:
  explicit CountingDevice(ReferencePathDevice& device) : device_(device) {}
  bool lights_match(const std::vector<kernels::ShadeLight>& l, const Sky& s) const override {
    return device_.lights_match(l, s);
  }
  uint64_t max_paths() const override { return device_.max_paths(); }
  std::string name() const override { return device_.name(); }
  Status trace(const std::vector<ReferencePoint>& points, const ReferencePathParams& params,
               std::vector<ReferencePointSums>& out) override {
    traced += points.size();
    return device_.trace(points, params, out);
  }
  Status end_paths_in(const loader::BakeFile* file) override {
    const Status st = device_.end_paths_in(file);
    fields_set += file && st.is_ok();
    return st;
  }
  size_t traced = 0, fields_set = 0;

 private:
  ReferencePathDevice& device_;
};

DdgiResult field_volume(int n, loader::Vec3 grid_min, float spacing, uint32_t seed) {
  DdgiResult r = test::make_ddgi(n, n, n, 2, seed);
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = grid_min[a];
    r.desc.spacing[a] = spacing;
    r.desc.grid_max[a] = grid_min[a] + spacing * float(n - 1);
  }
  return r;
}

// The surface fit's paths with both estimates (trace_surface_irradiance, whole_paths_too) where the
// device reads the probes itself (path_probe_field.comp, the GLSL sampler over pack_probe_field's
// buffers): each point's whole paths and the same paths ended at their first hit in a field of two
// volumes (a finer one inside a coarse one, f16 and f32, the file's volume index) match the CPU's,
// which ends them through the loader, within float rounding; the device was asked for both.
TEST(GpuReferencePaths, PathsEndedInTheProbesMatchTheCpu) {
  const SunlitFloorAndWall lit;
  DeviceScene d;
  if (!open_scene(lit.scene, lit.lights, lit.sky, d)) GTEST_SKIP() << "no Vulkan device";
  const std::string settings = kSunlitSettings;
  const DdgiResult coarse = field_volume(5, {-3.f, 0.2f, -3.f}, 1.2f, 71);
  const DdgiResult fine = field_volume(4, {-1.f, 0.1f, -1.f}, 0.6f, 72);
  std::vector<VisibleSurface> points;
  for (int i = 0; i < 48; ++i) {
    const uint64_t key = kernels::rng_hash(5, uint64_t(i), 0, 0);
    const float u = kernels::rng_uniform(key, 0), v = kernels::rng_uniform(key, 1);
    if (i % 3 == 2)  // on the wall, facing -x
      points.push_back({true, {1.1f, 0.2f + 2.5f * u, -2.f + 4.f * v}, {-1.f, 0.f, 0.f}, {-1.f, 0.f, 0.f}});
    else  // on the floor
      points.push_back({true, {-2.5f + 3.5f * u, 0.f, -2.f + 4.f * v}, {0.f, 1.f, 0.f}, {0.f, 1.f, 0.f}});
  }
  for (FloatPrecision precision : {FloatPrecision::Half, FloatPrecision::Full}) {
    BakeFileOptions options;
    options.sh = precision;
    options.atlas = precision;
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(test::multi_volume_bytes({&coarse, &fine}, options, bytes).is_ok());
    loader::BakeFile file;
    ASSERT_FALSE(file.open_borrowed(bytes.data(), bytes.size()));
    ASSERT_TRUE(file.ddgi_index().present());
    const BakeFileProbeField field(file);
    std::vector<SurfaceLight> cpu, gpu;
    ASSERT_TRUE(
        trace_surface_irradiance(*d.prepared, d.lod, settings, points, 64, 9, nullptr, Context{}, cpu, &field, true));
    std::unique_ptr<ReferencePathDevice> device = make_gpu_reference_paths(d.session, true);
    ASSERT_NE(device, nullptr);
    CountingDevice counting(*device);
    const Status traced =
        trace_surface_irradiance(*d.prepared, d.lod, settings, points, 64, 9, &counting, Context{}, gpu, &field, true);
    ASSERT_TRUE(traced) << traced.message();
    EXPECT_EQ(counting.fields_set, 1u) << "the device did not take the probe field";
    EXPECT_EQ(counting.traced, points.size()) << "the device did not trace every point";
    ASSERT_EQ(cpu.size(), gpu.size());
    double worst = 0.0;
    size_t differ = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
      const kernels::float3 pairs[2][2] = {{cpu[i].irradiance, gpu[i].irradiance},
                                           {cpu[i].probe_lit, gpu[i].probe_lit}};
      for (const auto& pair : pairs)
        for (int k = 0; k < 3; ++k) {
          const float a = (&pair[0].x)[k], b = (&pair[1].x)[k];
          worst = std::max(worst, std::fabs(double(b) - a) / std::max(1e-3, double(std::fabs(a))));
          EXPECT_NEAR(b, a, 1e-4 * std::fabs(a) + 1e-4) << "point " << i << " channel " << k;
        }
      for (int h = 0; h < 2; ++h) {
        EXPECT_NEAR(gpu[i].half[h], cpu[i].half[h], 1e-4 * std::fabs(cpu[i].half[h]) + 1e-4) << i;
        EXPECT_NEAR(gpu[i].probe_half[h], cpu[i].probe_half[h], 1e-4 * std::fabs(cpu[i].probe_half[h]) + 1e-4) << i;
      }
      differ += std::fabs(cpu[i].probe_lit.x - cpu[i].irradiance.x) > 0.05f * cpu[i].irradiance.x;
    }
    std::printf("%s: %zu points, largest relative difference %.2e, ended unlike whole at %zu\n",
                precision == FloatPrecision::Half ? "f16" : "f32", cpu.size(), worst, differ);
    EXPECT_GT(differ, cpu.size() / 2) << "the probes' light must matter: the test shows nothing";
  }
  GIBAKE_EXPECT_NO_VALIDATION_ERRORS(d.session->vk);
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
  // Each path's radiance ended in a probe field (the xyz of the first of its three vec4s:
  // probe_field_ended.comp), summed alike with flags.x; the other words are never read.
  const float ended_rgb[6][3] = {{0.5f, 0.f, 0.f}, {0.f, 0.25f, 0.f}, {1.f, 1.f, 1.f},
                                 {0.f, 0.f, 4.f},  {2.f, 0.f, 0.f},   {0.f, 0.f, 0.f}};
  std::vector<float> ended(6 * 12, 99.f);
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < 3; ++k) ended[size_t(12 * i + k)] = ended_rgb[i][k];
  vk::Buffer in, out, ended_in;
  ASSERT_TRUE(vk->create_buffer(briefs.size() * sizeof(gpu::GpuPathBrief), in, "briefs"));
  ASSERT_TRUE(vk->create_buffer(2 * sizeof(gpu::GpuReferenceSums), out, "sums"));
  ASSERT_TRUE(vk->create_buffer(ended.size() * sizeof(float), ended_in, "ended"));
  ASSERT_TRUE(vk->upload(in, briefs.data(), briefs.size() * sizeof(gpu::GpuPathBrief)));
  ASSERT_TRUE(vk->upload(ended_in, ended.data(), ended.size() * sizeof(float)));
  vk::Dispatch d;
  d.pipeline = &sums;
  d.buffers = {&in, &out, &ended_in};
  d.push = vk::push_bytes(gpu::ReferenceSumsPush{{2u, 3u, 0u, GPU_RAY_WINDOW}, {1u, 0u, 0u, 0u}});
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
  EXPECT_FLOAT_EQ(got[0].ended.x, 1.5f);  // paths 0, 1 (untraced: its light sample) and 2
  EXPECT_FLOAT_EQ(got[0].ended.y, 1.25f);
  EXPECT_FLOAT_EQ(got[0].ended.z, 1.f);
  EXPECT_FLOAT_EQ(got[0].ended.w, lum(0.5f, 0.f, 0.f));                           // half 0: path 0
  EXPECT_FLOAT_EQ(got[0].half_lum.y, lum(0.f, 0.25f, 0.f) + lum(1.f, 1.f, 1.f));  // half 1
  EXPECT_FLOAT_EQ(got[1].ended.x, 2.f);
  EXPECT_FLOAT_EQ(got[1].ended.z, 4.f);
  // Without flags.x the ended sums stay zero, whatever binding 2 holds.
  vk::Dispatch plain = d;
  plain.push = vk::push_bytes(gpu::ReferenceSumsPush{{2u, 3u, 0u, GPU_RAY_WINDOW}, {0u, 0u, 0u, 0u}});
  ASSERT_TRUE(vk->run({plain}));
  gpu::GpuReferenceSums none[2];
  ASSERT_TRUE(vk->download(out, none, sizeof(none)));
  EXPECT_EQ(none[0].ended.x, 0.f);
  EXPECT_EQ(none[1].ended.z, 0.f);
  EXPECT_EQ(none[0].half_lum.y, 0.f);
  EXPECT_EQ(none[0].sum.x, got[0].sum.x);
  // In windows of two paths, then one: each continues the sums the one before stored, to the bit.
  vk::Dispatch w0 = d, w1 = d;
  w0.push = vk::push_bytes(gpu::ReferenceSumsPush{{2u, 3u, 0u, 2u}, {1u, 0u, 0u, 0u}});
  w1.push = vk::push_bytes(gpu::ReferenceSumsPush{{2u, 3u, 2u, 2u}, {1u, 0u, 0u, 0u}});
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
