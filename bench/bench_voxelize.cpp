// Voxelization of Sponza at 256 voxels on the longest axis: ours (occupancy only, with every
// channel, with channels + a sun's direct light + SDF) beside OpenVDB's meshToVolume on the same
// mesh, transform and voxel size. Counters: triangles/s. Figures: docs/BENCHMARKS.md.
#include <benchmark/benchmark.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cstdio>
#include <cstdlib>

#include "bake/scene/lights.h"
#include "bake/voxel/voxelize.h"
#include "io/gltf/import.h"

namespace {
using namespace gibake;

const Scene& sponza() {
  static Scene scene = [] {
    Scene s;
    const char* env = std::getenv("GIBAKE_VOXEL_BENCH_SCENE");
    const std::string path = env ? env : std::string(GIBAKE_ASSETS_DIR) + "/sponza/Sponza.gltf";
    if (Status st = import_scene(path, ImportOptions{}, Context{}, s); !st) {
      std::fprintf(stderr, "bench_voxelize: %s\n", st.message().c_str());
      std::exit(2);
    }
    return s;
  }();
  return scene;
}

int32_t resolution() {
  const char* env = std::getenv("GIBAKE_VOXEL_BENCH_RES");
  return env ? std::atoi(env) : 256;
}

void run_ours(benchmark::State& state, bool channels, bool sdf, bool sun) {
  const Scene& s = sponza();
  VoxelSettings vs;
  vs.resolution = resolution();
  vs.channels = channels;
  vs.sdf = sdf;
  SunLight light;
  light.direction = {0.3f, -1.f, 0.2f};
  light.lux = 100000.f;
  const auto lights = sun ? shade_lights(s, {light}) : std::vector<kernels::ShadeLight>{};
  VoxelReport rep;
  for (auto _ : state) {
    VoxelGrid g;
    if (Status st = voxelize(s, vs, lights, nullptr, Context{}, g, &rep); !st) state.SkipWithError(st.message().c_str());
    benchmark::DoNotOptimize(g.surface.data());
  }
  state.counters["triangles/s"] = benchmark::Counter(double(s.triangle_count()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["surface_voxels"] = double(rep.surface_voxels);
  state.counters["fragments"] = double(rep.fragments);
  for (const auto& [stage, sec] : rep.stage_seconds) state.counters[stage + "_s"] = sec;
}

void BM_Ours_Occupancy(benchmark::State& st) { run_ours(st, false, false, false); }
void BM_Ours_Channels(benchmark::State& st) { run_ours(st, true, false, false); }
void BM_Ours_ChannelsSunSdf(benchmark::State& st) { run_ours(st, true, true, true); }

// OpenVDB on the same transform as ours: band 1 (unsigned; voxelization only, the closest
// analogue of occupancy) and the signed level set meshToVolume makes by default (3 voxels each side,
// meshToSignedDistanceField).
void run_openvdb(benchmark::State& state, bool signed_band3) {
  const Scene& s = sponza();
  VoxelSettings vs;
  vs.resolution = resolution();
  VoxelGrid layout;
  uint64_t est = 0;
  if (!plan_voxel_grid(s, vs, layout, est)) state.SkipWithError("plan failed");
  openvdb::initialize();
  std::vector<openvdb::Vec3s> pts(s.vertex_count());
  for (size_t i = 0; i < pts.size(); ++i) pts[i] = openvdb::Vec3s(&s.positions[i * 3]);
  std::vector<openvdb::Vec3I> tris(s.triangle_count());
  for (size_t t = 0; t < tris.size(); ++t) tris[t] = openvdb::Vec3I(&s.indices[t * 3]);
  const double h = layout.voxel_size;
  auto xf = openvdb::math::Transform::createLinearTransform(h);
  xf->postTranslate(openvdb::Vec3d(layout.origin[0] + 0.5 * h, layout.origin[1] + 0.5 * h, layout.origin[2] + 0.5 * h));
  size_t active = 0;
  for (auto _ : state) {
    openvdb::FloatGrid::Ptr g =
        signed_band3 ? openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(*xf, pts, tris, {}, 3.f, 3.f)
                     : openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xf, pts, tris, {}, 1.f);
    active = g->activeVoxelCount();
    benchmark::DoNotOptimize(g.get());
  }
  state.counters["triangles/s"] = benchmark::Counter(double(s.triangle_count()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["active_voxels"] = double(active);
}

void BM_OpenVdb_Unsigned1(benchmark::State& st) { run_openvdb(st, false); }
void BM_OpenVdb_MeshToVolume(benchmark::State& st) { run_openvdb(st, true); }

BENCHMARK(BM_Ours_Occupancy)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_OpenVdb_Unsigned1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_OpenVdb_MeshToVolume)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_Ours_Channels)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_Ours_ChannelsSunSdf)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
