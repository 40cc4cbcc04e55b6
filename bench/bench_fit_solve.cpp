// The surface fit's solve (bake/ddgi/fit_solve.h) on a synthetic system shaped like `final`'s on
// Sponza: probes on a grid with 8x8-texel tiles, surface points on floors and walls each reading
// the 8 probes around them (trilinear weights) at the 4 texels around the surface's normal
// (bilinear), every row scaled to the baked value 1, targets near 1 with a smooth field and noise;
// a texel pulled towards its tile's gain by 0.075, a tile's gain towards 1 by 10 (final's priors).
// Two formulations of the same problem:
//   Explicit: the tiles' gains as columns of their own, each entry read by its texel's deviation
//             and its tile's gain (what the fit solved before the gains were eliminated);
//   Eliminated: the texels' whole gains with their tiles as groups (what the fit solves now).
// Counters: the solve's iterations, unknowns and entries. That the two have one solution is
// tests/bake/fit_solve_test.cpp's (the elimination against a dense solve of the explicit system).
// A real fit's rows are uneven in ways this one is not (the points' trust, several volumes' shares,
// probes behind the surface left out), and it takes several times the iterations: this measures
// an iteration's cost and what the elimination saves of it.
//   bench_fit_solve --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "bake/ddgi/fit_solve.h"

namespace gibake {
namespace {

constexpr int kTile = 8;  // texels a side
constexpr double kTexelPull = 0.075, kTilePull = 10.0;

struct Problems {
  SparseLeastSquares explicit_tiles, eliminated;
};

// `points` rows over a grid of n x n x n/2 probes.
Problems make_problems(int n, size_t points) {
  const int nx = n, ny = n / 2, nz = n;
  const size_t tiles = size_t(nx) * ny * nz, texels = tiles * kTile * kTile;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  // Columns numbered in the order points first read them, as the fit numbers them; the explicit
  // system's tile columns (after every texel's) are filled in once the texels are counted.
  std::vector<int32_t> texel_id(texels, -1), tile_id(tiles, -1);
  std::vector<size_t> texel_tile;  // per read texel
  std::vector<uint32_t> e_tile;    // per tile entry of the explicit system
  size_t tiles_read = 0;
  Problems p;
  SparseLeastSquares& e = p.explicit_tiles;
  SparseLeastSquares& s = p.eliminated;
  e.row_start.push_back(0), s.row_start.push_back(0);
  for (size_t r = 0; r < points; ++r) {
    // Points on surfaces: floors (every fourth probe layer, a little above it) facing up, walls
    // (every sixth column of probes across x) facing +x or -x, so that the probes beside a
    // surface are read heavily and those a cell off lightly. The texel around the normal's
    // octahedral place, jittered by a quarter texel, and its bilinear weights.
    double at[3] = {u(rng) * (nx - 1), u(rng) * (ny - 1), u(rng) * (nz - 1)};
    static const double kFacing[3][2] = {{3.5, 3.5}, {0.5, 3.5}, {6.5, 3.5}};
    const int facing = int(u(rng) * 3) % 3;
    if (facing == 0)
      at[1] = std::min(double(ny - 1), 4.0 * std::floor(at[1] / 4.0) + 0.1 + 0.2 * u(rng));
    else
      at[0] = std::min(double(nx - 1), 6.0 * std::floor(at[0] / 6.0) + (facing == 1 ? 0.15 : 5.85));
    const double tx = std::clamp(kFacing[facing][0] + (u(rng) - 0.5) * 0.5, 0.0, kTile - 1.001);
    const double ty = std::clamp(kFacing[facing][1] + (u(rng) - 0.5) * 0.5, 0.0, kTile - 1.001);
    const int x0 = int(tx), y0 = int(ty);
    const double fx = tx - x0, fy = ty - y0;
    for (int corner = 0; corner < 8; ++corner) {
      int c[3];
      double w = 1.0;
      for (int a = 0; a < 3; ++a) {
        const int lo = std::min(int(at[a]), (a == 1 ? ny : nx) - 2);
        const double f = at[a] - lo;
        c[a] = lo + ((corner >> a) & 1);
        w *= (corner >> a) & 1 ? f : 1.0 - f;
      }
      const size_t tile = (size_t(c[2]) * ny + size_t(c[1])) * nx + size_t(c[0]);
      for (int k = 0; k < 4; ++k) {
        const int x = x0 + (k & 1), y = y0 + (k >> 1);
        const double a = w * ((k & 1) ? fx : 1.0 - fx) * ((k >> 1) ? fy : 1.0 - fy) * (0.5 + u(rng));
        if (!(a > 1e-6)) continue;
        const size_t texel = tile * kTile * kTile + size_t(y) * kTile + size_t(x);
        if (texel_id[texel] < 0) texel_id[texel] = int32_t(texel_tile.size()), texel_tile.push_back(tile);
        if (tile_id[tile] < 0) tile_id[tile] = int32_t(tiles_read++);
        s.column.push_back(uint32_t(texel_id[texel])), s.value.push_back(float(a));
        e.column.push_back(uint32_t(texel_id[texel])), e.value.push_back(float(a));
        e_tile.push_back(uint32_t(tile_id[tile])), e.column.push_back(0), e.value.push_back(float(a));
      }
    }
    // Rows scaled to the baked value: their entries sum to 1.
    double sum = 0.0;
    for (size_t k = s.row_start.back(); k < s.column.size(); ++k) sum += s.value[k];
    for (size_t k = s.row_start.back(); k < s.column.size(); ++k) s.value[k] = float(s.value[k] / sum);
    for (size_t k = e.row_start.back(); k < e.column.size(); ++k) e.value[k] = float(e.value[k] / sum);
    s.row_start.push_back(s.column.size()), e.row_start.push_back(e.column.size());
    const double truth = 1.0 + 0.3 * std::sin(at[0] * 0.4) * std::cos(at[2] * 0.3) + 0.2 * g(rng);
    s.rhs_row.push_back(truth), e.rhs_row.push_back(truth);
  }
  const size_t read = texel_tile.size();
  size_t next_tile = 0;
  for (size_t k = 1; k < e.column.size(); k += 2) e.column[k] = uint32_t(read + e_tile[next_tile++]);
  index_columns(s, read);
  index_columns(e, read + tiles_read);
  s.prior.assign(read, kTexelPull), s.target.assign(read, 1.0);
  for (size_t t = 0; t < read; ++t) s.group.push_back(tile_id[texel_tile[t]]);
  s.group_prior.assign(tiles_read, kTilePull), s.group_target.assign(tiles_read, 1.0);
  e.prior.assign(read, kTexelPull), e.target.assign(read, 0.0);
  e.prior.resize(read + tiles_read, kTilePull), e.target.resize(read + tiles_read, 1.0);
  return p;
}

const Problems& problems() {
  static const Problems p = make_problems(40, 400000);  // 32,000 tiles, final's 400,000 points
  return p;
}

void solve(benchmark::State& state, const SparseLeastSquares& system) {
  std::vector<double> x;
  int iterations = 0;
  for (auto _ : state) {
    iterations = solve_least_squares(system, x);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["iterations"] = iterations;
  state.counters["unknowns"] = double(system.prior.size());
  state.counters["entries"] = double(system.value.size());
}

void BM_FitSolveExplicitTiles(benchmark::State& state) { solve(state, problems().explicit_tiles); }
void BM_FitSolveEliminated(benchmark::State& state) { solve(state, problems().eliminated); }

BENCHMARK(BM_FitSolveExplicitTiles)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FitSolveEliminated)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace gibake

BENCHMARK_MAIN();
