// The surface fit's ended paths reading the probes (bake/trace/probe_field_cache.h): the sampler
// at every hit against one read per cube, plane and normal bin. The volume is
// bench_ddgi_sample's shape (38 x 21 x 18 probes 1 m apart, binary16 atlases, probe-major tiles);
// the hits are those of points walking through it 5 cm apart, 144 paths a point, each path's
// first hit on the nearest wall of a lattice of 2 m rooms (axis planes every 2 m) in a
// cosine-weighted direction about the point's floor. Cubes of a quarter of the spacing, as the
// default's SurfaceFitSettings::read_cell. One thread.
//   bench_fit_reads --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <vector>

#include "bake/trace/probe_field_cache.h"
#include "bench/sponza_shaped_volume.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"
#include "kernels/ray_gen.h"

namespace gibake {
namespace {

using kernels::float3;

struct Hit {
  float3 p, n;
};

// The first wall of the 2 m lattice that the ray from `o` along `d` meets.
Hit first_wall(const float3& o, const float3& d) {
  constexpr float kRoom = 2.f;
  float best = 1e30f;
  int axis = 0;
  const float oc[3] = {o.x, o.y, o.z}, dc[3] = {d.x, d.y, d.z};
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(dc[a]) < 1e-6f) continue;
    const float wall = dc[a] > 0.f ? std::ceil(oc[a] / kRoom) * kRoom : std::floor(oc[a] / kRoom) * kRoom;
    const float t = (wall - oc[a]) / dc[a];
    if (t > 0.f && t < best) best = t, axis = a;
  }
  float3 n{0.f, 0.f, 0.f};
  (axis == 0 ? n.x : axis == 1 ? n.y : n.z) = dc[axis] > 0.f ? -1.f : 1.f;
  return Hit{o + d * best, n};
}

struct Volume {
  std::vector<uint8_t> bytes;
  loader::BakeFile file;
};

const Volume& volume() {
  static std::unique_ptr<Volume> v;
  if (v) return *v;
  v = std::make_unique<Volume>();
  const DdgiResult r = sponza_shaped_volume(false);
  BakeOutputs out;
  out.ddgi = &r;
  BakeFileOptions options;
  options.atlas = FloatPrecision::Half;
  if (!build_bake_file(out, options, v->bytes).is_ok() ||
      v->file.open_borrowed(v->bytes.data(), v->bytes.size(), loader::LoadOptions{false, true}))
    std::abort();
  return *v;
}

// Hit `i` of the stream: point i / 144 on the floors (y = 2k + 0.01), walking 5 cm a point along x,
// then up a floor, then 0.3 m along z (about 39 M hits before the walk comes back), its path
// i % 144 drawn cosine-weighted about +y.
Hit hit(uint64_t i) {
  constexpr uint64_t kPaths = 144;
  const uint64_t point = i / kPaths;
  const float walk = 0.05f * float(point % 680);
  const uint64_t row = point / 680;
  const float3 at{1.f + walk, 2.01f + 2.f * float(row % 8), 1.f + 0.3f * float((row / 8) % 50)};
  const float u0 = kernels::rng_uniform(i, 0), u1 = kernels::rng_uniform(i, 1);
  const float phi = 6.2831853f * u0, sr = std::sqrt(u1);
  return first_wall(at, float3{sr * std::cos(phi), std::sqrt(1.f - u1), sr * std::sin(phi)});
}

void BM_ReadsAtEveryHit(benchmark::State& state) {
  const BakeFileProbeField field(volume().file);
  uint64_t i = 0;
  for (auto _ : state) {
    const Hit h = hit(i++);
    benchmark::DoNotOptimize(field.irradiance(h.p, h.n));
  }
}

void BM_ReadsSharedPerCube(benchmark::State& state) {
  const BakeFileProbeField field(volume().file);
  const CachedProbeField shared(field, 0.25f, CachedProbeField::table_bits_for(1));
  const Hit first = hit(0);
  benchmark::DoNotOptimize(shared.irradiance(first.p, first.n));  // the table made before the timing
  uint64_t i = 0;
  for (auto _ : state) {
    const Hit h = hit(i++);
    benchmark::DoNotOptimize(shared.irradiance(h.p, h.n));
  }
}

// The stream alone: what both of the above spend before reading.
void BM_HitsAlone(benchmark::State& state) {
  uint64_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(hit(i++));
}

BENCHMARK(BM_ReadsAtEveryHit);
BENCHMARK(BM_ReadsSharedPerCube);
BENCHMARK(BM_HitsAlone);

}  // namespace
}  // namespace gibake

BENCHMARK_MAIN();
