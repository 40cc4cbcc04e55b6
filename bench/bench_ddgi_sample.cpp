// The CPU sampler (DdgiVolume::try_sample_irradiance) on a volume of Sponza's default grid's shape
// (38 x 21 x 18 probes 1 m apart, a third of them inactive, binary16 irradiance and depth atlases
// of the bake's tile sizes) at random points and normals, reading the atlases' rows as the file
// holds them against the probe-major copies of LoadOptions::probe_major_tiles. The answers are
// the same to the bit (tests/loader/sampler_test.cpp); this measures what the copies save when
// queries scatter over the volume, as the surface fit's ended paths do.
//   bench_ddgi_sample --benchmark_min_time=0.5
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>

#include "bench/sponza_shaped_volume.h"
#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"

namespace gibake {
namespace {

struct Volume {
  std::vector<uint8_t> bytes;
  loader::BakeFile rows, tiles;
  std::vector<loader::Vec3> points, normals;
};

const Volume& volume() {
  static std::unique_ptr<Volume> v;
  if (v) return *v;
  v = std::make_unique<Volume>();
  const DdgiResult r = sponza_shaped_volume(true);
  BakeOutputs out;
  out.ddgi = &r;
  BakeFileOptions options;
  options.atlas = FloatPrecision::Half;
  if (!build_bake_file(out, options, v->bytes).is_ok() || v->rows.open_borrowed(v->bytes.data(), v->bytes.size()) ||
      v->tiles.open_borrowed(v->bytes.data(), v->bytes.size(), loader::LoadOptions{true, true}))
    std::abort();
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  for (int i = 0; i < (1 << 16); ++i) {
    v->points.push_back({37.f * u(rng), 20.f * u(rng), 17.f * u(rng)});
    loader::Vec3 n{g(rng), g(rng), g(rng)};
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    v->normals.push_back({n[0] / l, n[1] / l, n[2] / l});
  }
  return *v;
}

void run(benchmark::State& state, bool tiles) {
  const Volume& v = volume();
  const loader::DdgiVolume& d = (tiles ? v.tiles : v.rows).ddgi_volumes()[0];
  size_t i = 0;
  loader::Rgb e;
  for (auto _ : state) {
    const size_t k = i++ & ((1 << 16) - 1);
    benchmark::DoNotOptimize(d.try_sample_irradiance(v.points[k], v.normals[k], e));
    benchmark::DoNotOptimize(e);
  }
  state.counters["tile_MiB"] = double(d.probe_tile_bytes()) / (1024.0 * 1024.0);
}

void BM_AtlasRows(benchmark::State& state) { run(state, false); }
void BM_ProbeMajorTiles(benchmark::State& state) { run(state, true); }
BENCHMARK(BM_AtlasRows);
BENCHMARK(BM_ProbeMajorTiles);

}  // namespace
}  // namespace gibake

BENCHMARK_MAIN();
