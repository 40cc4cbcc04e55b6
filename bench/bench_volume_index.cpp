// BakeFile::sample_ddgi through the DDGI volume index (format 1.4) against the loop over every
// volume (sample_ddgi_unindexed), on a synthetic file of a coarse 24x6x24 grid under N small fine
// volumes (4x3x4 probes, 0.25-0.5 m spacing, scattered over 40 x 40 m), at random points over the
// scene and random normals. The answers are bit-identical (tests/loader/volume_index_test.cpp);
// this measures what the index saves on the CPU.
//   bench_volume_index --benchmark_min_time=0.3
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>

#include "gibake/loader.hpp"
#include "io/bakefile/bake_file.h"

namespace gibake {
namespace {

DdgiResult make_volume(std::array<int, 3> counts, std::array<float, 3> grid_min, float spacing, uint32_t seed) {
  DdgiResult r;
  r.desc.counts = counts;
  r.desc.sh_order = 2;
  r.desc.max_distance = 50.f;
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = grid_min[a];
    r.desc.spacing[a] = spacing;
    r.desc.grid_max[a] = grid_min[a] + spacing * float(counts[a] - 1);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const size_t n = size_t(r.desc.probe_count());
  for (size_t i = 0; i < n * 27; ++i) r.sh.push_back(i % 27 < 3 ? 1.f + 5.f * u(rng) : 0.2f * (u(rng) - 0.5f));
  return r;
}

struct Scene {
  std::vector<uint8_t> bytes;
  loader::BakeFile file;
  std::vector<loader::Vec3> points, normals;
};

const Scene& scene(int fine) {
  static std::map<int, std::unique_ptr<Scene>> cache;
  std::unique_ptr<Scene>& s = cache[fine];
  if (s) return *s;
  s = std::make_unique<Scene>();
  std::vector<DdgiResult> volumes{make_volume({24, 6, 24}, {-20.f, 0.f, -20.f}, 40.f / 23.f, 1)};
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int k = 0; k < fine; ++k)
    volumes.push_back(make_volume({4, 3, 4}, {-19.f + 37.f * u(rng), 8.f * u(rng), -19.f + 37.f * u(rng)},
                                  0.25f + 0.25f * u(rng), 10 + uint32_t(k)));
  BakeOutputs out;
  out.ddgi = &volumes[0];
  for (size_t v = 1; v < volumes.size(); ++v) out.ddgi_more.push_back(&volumes[v]);
  if (!build_bake_file(out, BakeFileOptions{}, s->bytes).is_ok() || s->file.open_borrowed(s->bytes.data(), s->bytes.size()))
    std::abort();
  std::normal_distribution<float> g(0.f, 1.f);
  for (int i = 0; i < 4096; ++i) {
    s->points.push_back({-21.f + 42.f * u(rng), -1.f + 11.f * u(rng), -21.f + 42.f * u(rng)});
    loader::Vec3 n{g(rng), g(rng), g(rng)};
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    s->normals.push_back({n[0] / l, n[1] / l, n[2] / l});
  }
  return *s;
}

void run(benchmark::State& state, bool indexed) {
  const Scene& s = scene(int(state.range(0)));
  size_t i = 0;
  loader::Rgb e;
  for (auto _ : state) {
    const size_t k = i++ & 4095;
    const bool in = indexed ? s.file.sample_ddgi(s.points[k], s.normals[k], e)
                            : s.file.sample_ddgi_unindexed(s.points[k], s.normals[k], e);
    benchmark::DoNotOptimize(in);
    benchmark::DoNotOptimize(e);
  }
  state.counters["cells"] = double(s.file.ddgi_index().desc().cell_count);
  state.counters["longest_list"] = double(s.file.ddgi_index().desc().longest);
}

void BM_Indexed(benchmark::State& state) { run(state, true); }
void BM_Loop(benchmark::State& state) { run(state, false); }
BENCHMARK(BM_Indexed)->Arg(8)->Arg(40)->Arg(160);
BENCHMARK(BM_Loop)->Arg(8)->Arg(40)->Arg(160);

}  // namespace
}  // namespace gibake

BENCHMARK_MAIN();
