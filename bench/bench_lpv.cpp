// LPV propagation speed: cell updates per second per iteration. One propagation step =
// the flux-scale pass + the 6 x 5-face gather over every cell, double-buffered, with and without
// the geometry volume, single-threaded (the kernel) and over all threads (the stage's z-plane tasks).
//   build/bench/bench_lpv [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <vector>

#include "kernels/lpv.h"

namespace {

using gibake::kernels::LpvCell;
using gibake::kernels::LpvGrid;

struct Fixture {
  LpvGrid grid;
  std::vector<LpvCell> src, dst;
  std::vector<float> scale, geometry;
  explicit Fixture(int n) {
    grid.dims[0] = grid.dims[1] = grid.dims[2] = n;
    src.resize(grid.cells());
    dst.resize(grid.cells());
    scale.resize(grid.cells() * 3);
    geometry.assign(gibake::kernels::lpv_geometry_corners(grid) * 4, 0.f);
    // Light everywhere (a fully lit volume: no cell is skipped) and a wall of geometry every 8 cells.
    for (size_t i = 0; i < src.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        src[i].sh[c][0] = 1.f + float(i % 7);
        src[i].sh[c][1] = 0.3f;
        src[i].sh[c][3] = -0.2f;
      }
    for (int z = 0; z <= n; ++z)
      for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; x += 8) {
          const int32_t corner[3] = {x, y, z};
          gibake::kernels::lpv_geometry_add(grid, corner, 1.f, {-1.f, 0.f, 0.f}, geometry.data());
        }
  }
};

void BM_LpvPropagate(benchmark::State& state) {
  const int n = int(state.range(0));
  const bool occlusion = state.range(1) != 0;
  const bool parallel = state.range(2) != 0;
  Fixture f(n);
  for (auto _ : state) {
    if (parallel) {
      tbb::parallel_for(tbb::blocked_range<int>(0, n, 1), [&](const tbb::blocked_range<int>& r) {
        gibake::kernels::lpv_flux_scale(f.grid, f.src.data(), f.scale.data(), r.begin(), r.end());
      });
      tbb::parallel_for(tbb::blocked_range<int>(0, n, 1), [&](const tbb::blocked_range<int>& r) {
        gibake::kernels::lpv_propagate(f.grid, f.src.data(), f.scale.data(), occlusion ? f.geometry.data() : nullptr,
                                       f.dst.data(), r.begin(), r.end());
      });
    } else {
      gibake::kernels::lpv_flux_scale(f.grid, f.src.data(), f.scale.data(), 0, n);
      gibake::kernels::lpv_propagate(f.grid, f.src.data(), f.scale.data(), occlusion ? f.geometry.data() : nullptr,
                                     f.dst.data(), 0, n);
    }
    benchmark::DoNotOptimize(f.dst.data());
    benchmark::ClobberMemory();
  }
  state.counters["cell_updates_per_s"] =
      benchmark::Counter(double(f.grid.cells()) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LpvPropagate)
    ->ArgNames({"res", "occlusion", "threads_all"})
    ->Args({32, 0, 0})
    ->Args({32, 1, 0})
    ->Args({64, 0, 0})
    ->Args({64, 1, 0})
    ->Args({64, 0, 1})
    ->Args({64, 1, 1})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
