// The surface fit's solve (bake/ddgi/fit_solve.h) against a dense direct solve of the same normal
// equations, on a system shaped like a fit's: a few unknowns that thousands of rows read beside
// many that a handful read, with small entries, held mostly by their priors. Every unknown, the
// lightly read ones included, must reach the solution, and the thread count must not matter. With
// groups (the fit's texels and their probe tiles) the solve eliminates the group values: its answer
// must be the solution of the system that keeps them as unknowns of their own. Rows scaled by the
// solution (the fit's second solve) must weigh each residual by the first solution's own value of
// its row, which a dense solve of the rows as the test scales them confirms.
#include "bake/ddgi/fit_solve.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <vector>

namespace gibake {
namespace {

constexpr uint32_t kHeavy = 8, kLight = 48, kColumns = kHeavy + kLight;

// Rows of four entries: three heavy unknowns weighed near 1 and, in one row in 400, a light one
// weighed 0.02-0.1; right-hand sides near 1, the light rows' far from what the heavy ones explain.
SparseLeastSquares fit_shaped_system() {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  SparseLeastSquares s;
  std::vector<std::vector<std::pair<uint32_t, float>>> rows;
  for (int r = 0; r < 20000; ++r) {
    std::vector<std::pair<uint32_t, float>> row;
    for (int k = 0; k < 3; ++k) row.emplace_back(uint32_t(random() % kHeavy), 0.5f + unit(random));
    const bool light = r % 400 == 0;
    if (light) row.emplace_back(kHeavy + uint32_t(random() % kLight), 0.02f + 0.08f * unit(random));
    rows.push_back(row);
    s.rhs_row.push_back((light ? 3.0 : 1.0) + 0.2 * unit(random));
  }
  s.row_start.push_back(0);
  for (const auto& row : rows) {
    for (const auto& [c, v] : row) s.column.push_back(c), s.value.push_back(v);
    s.row_start.push_back(s.column.size());
  }
  index_columns(s, kColumns);
  for (uint32_t c = 0; c < kColumns; ++c) {
    s.prior.push_back(c < kHeavy ? 10.0 : 0.075);  // the fit's probe and final-level texel pulls
    s.target.push_back(c < kHeavy ? 1.0 : 0.0);
  }
  return s;
}

// (A^T A + diag(prior)) x = A^T t + prior x target by Gaussian elimination with partial pivoting.
std::vector<double> dense_solution(const SparseLeastSquares& s) {
  const size_t n = s.prior.size();
  std::vector<std::vector<double>> m(n, std::vector<double>(n + 1, 0.0));
  for (size_t r = 0; r + 1 < s.row_start.size(); ++r)
    for (size_t i = s.row_start[r]; i < s.row_start[r + 1]; ++i) {
      for (size_t j = s.row_start[r]; j < s.row_start[r + 1]; ++j)
        m[s.column[i]][s.column[j]] += double(s.value[i]) * double(s.value[j]);
      m[s.column[i]][n] += double(s.value[i]) * s.rhs_row[r];
    }
  for (size_t c = 0; c < n; ++c) m[c][c] += s.prior[c], m[c][n] += s.prior[c] * s.target[c];
  for (size_t k = 0; k < n; ++k) {
    size_t pivot = k;
    for (size_t i = k + 1; i < n; ++i)
      if (std::fabs(m[i][k]) > std::fabs(m[pivot][k])) pivot = i;
    std::swap(m[k], m[pivot]);
    for (size_t i = k + 1; i < n; ++i) {
      const double f = m[i][k] / m[k][k];
      for (size_t j = k; j <= n; ++j) m[i][j] -= f * m[k][j];
    }
  }
  std::vector<double> x(n, 0.0);
  for (size_t k = n; k-- > 0;) {
    double s2 = m[k][n];
    for (size_t j = k + 1; j < n; ++j) s2 -= m[k][j] * x[j];
    x[k] = s2 / m[k][k];
  }
  return x;
}

TEST(FitSolve, EveryUnknownReachesTheSolutionTheLightlyReadOnesToo) {
  const SparseLeastSquares s = fit_shaped_system();
  const std::vector<double> exact = dense_solution(s);
  std::vector<double> x;
  const int iterations = solve_least_squares(s, x);
  ASSERT_EQ(x.size(), exact.size());
  EXPECT_LT(iterations, kFitSolveMaxIterations);
  double moved = 0.0;  // how far the light unknowns' solution is from their targets
  for (uint32_t c = 0; c < kColumns; ++c) {
    EXPECT_NEAR(x[c], exact[c], 2e-3) << "unknown " << c << (c < kHeavy ? " (heavy)" : " (light)");
    if (c >= kHeavy) moved = std::max(moved, std::fabs(exact[c] - s.target[c]));
  }
  EXPECT_GT(moved, 0.5) << "the light unknowns stay at their targets: the test shows nothing";
}

// The fit's shape with groups: columns c are texels of tile c % 8, the first 8 (one a tile) read by
// every row, the others by one row in 400. Returns the grouped system and, in `explicit_system`,
// the same problem with the tiles' gains as columns of their own (after the texels'): each entry
// also read by its tile's column, a texel's own deviation pulled towards 0.
SparseLeastSquares grouped_system(SparseLeastSquares& explicit_system) {
  SparseLeastSquares s = fit_shaped_system();
  constexpr uint32_t kTiles = 8;
  s.group.resize(kColumns);
  for (uint32_t c = 0; c < kColumns; ++c) s.group[c] = int32_t(c % kTiles), s.prior[c] = 0.075;
  s.group_prior.assign(kTiles, 10.0);
  s.group_target.assign(kTiles, 1.0);
  SparseLeastSquares& e = explicit_system;
  e = SparseLeastSquares{};
  e.row_start.push_back(0);
  for (size_t r = 0; r + 1 < s.row_start.size(); ++r) {
    for (size_t k = s.row_start[r]; k < s.row_start[r + 1]; ++k) {
      e.column.push_back(s.column[k]), e.value.push_back(s.value[k]);
      e.column.push_back(kColumns + s.column[k] % kTiles), e.value.push_back(s.value[k]);
    }
    e.row_start.push_back(e.column.size());
  }
  e.rhs_row = s.rhs_row;
  index_columns(e, kColumns + kTiles);
  e.prior.assign(kColumns, 0.075), e.target.assign(kColumns, 0.0);
  e.prior.resize(kColumns + kTiles, 10.0), e.target.resize(kColumns + kTiles, 1.0);
  return s;
}

TEST(FitSolve, GroupsEliminatedGiveTheSolutionWithTheGroupValuesAsUnknowns) {
  SparseLeastSquares with_tiles;
  const SparseLeastSquares s = grouped_system(with_tiles);
  const std::vector<double> exact = dense_solution(with_tiles);  // deviations, then the tiles' gains
  std::vector<double> x;
  const int iterations = solve_least_squares(s, x);
  ASSERT_EQ(x.size(), size_t(kColumns));
  EXPECT_LT(iterations, kFitSolveMaxIterations);
  const std::vector<double> tiles = group_values(s, x);
  ASSERT_EQ(tiles.size(), size_t(8));
  for (uint32_t g = 0; g < 8; ++g) EXPECT_NEAR(tiles[g], exact[kColumns + g], 2e-3) << "tile " << g;
  double moved = 0.0, shared = 0.0;  // how far the light texels and the tiles are from 1
  for (uint32_t c = 0; c < kColumns; ++c) {
    const double whole = exact[c] + exact[kColumns + c % 8];
    EXPECT_NEAR(x[c], whole, 2e-3) << "texel " << c << (c < kHeavy ? " (heavy)" : " (light)");
    if (c >= kHeavy) moved = std::max(moved, std::fabs(whole - 1.0));
  }
  for (uint32_t g = 0; g < 8; ++g) shared = std::max(shared, std::fabs(exact[kColumns + g] - 1.0));
  EXPECT_GT(moved, 0.5) << "the light texels stay at 1: the test shows nothing";
  EXPECT_GT(shared, 0.01) << "the tiles' gains stay at 1: the elimination is not exercised";
}

TEST(FitSolve, AGroupNothingPullsStaysFinite) {
  SparseLeastSquares unused;
  SparseLeastSquares s = grouped_system(unused);
  s.group_prior[0] = 0.0;  // group 0 and its columns pulled by nothing: only the rows hold them
  for (uint32_t c = 0; c < kColumns; ++c)
    if (s.group[c] == 0) s.prior[c] = 0.0;
  std::vector<double> x;
  solve_least_squares(s, x);
  for (uint32_t c = 0; c < kColumns; ++c) EXPECT_TRUE(std::isfinite(x[c])) << "column " << c;
  const std::vector<double> groups = group_values(s, x);
  EXPECT_EQ(groups[0], s.group_target[0]);
  for (double v : groups) EXPECT_TRUE(std::isfinite(v));
}

TEST(FitSolve, TheThreadCountDoesNotMatter) {
  const SparseLeastSquares s = fit_shaped_system();
  std::vector<double> one, many;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    solve_least_squares(s, one);
  }
  solve_least_squares(s, many);
  EXPECT_TRUE(one == many);
  SparseLeastSquares unused;
  const SparseLeastSquares grouped = grouped_system(unused);
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    solve_least_squares(grouped, one);
  }
  solve_least_squares(grouped, many);
  EXPECT_TRUE(one == many);
}

// Row r scaled by q_r^-p, q_r = (A x)_r / (A 1)_r within the bounds: against each row scaled here
// by hand (entries and target alike, so the row's ratio of solution to target, which the fit's
// figures read, is kept), and the solve after it against a dense solve of the scaled rows.
TEST(FitSolve, RowsScaledByTheSolutionWeighEachResidualByIt) {
  const SparseLeastSquares s = fit_shaped_system();
  std::vector<double> x;
  solve_least_squares(s, x);
  for (double exponent : {1.0, 0.5}) {
    SparseLeastSquares scaled = s;
    scale_rows_by_solution(scaled, x, exponent, 0.95, 1.2);
    size_t clamped = 0;
    double widest = 1.0, narrowest = 1.0;
    for (size_t r = 0; r + 1 < s.row_start.size(); ++r) {
      double solved = 0.0, before = 0.0;
      for (size_t k = s.row_start[r]; k < s.row_start[r + 1]; ++k)
        solved += double(s.value[k]) * x[s.column[k]], before += double(s.value[k]);
      const double q = solved / before, held = std::min(1.2, std::max(0.95, q)), f = std::pow(held, -exponent);
      clamped += held != q;
      widest = std::max(widest, f), narrowest = std::min(narrowest, f);
      for (size_t k = s.row_start[r]; k < s.row_start[r + 1]; ++k)
        ASSERT_NEAR(scaled.value[k], s.value[k] * f, 1e-6 * std::fabs(s.value[k])) << "row " << r;
      ASSERT_NEAR(scaled.rhs_row[r], s.rhs_row[r] * f, 1e-12 * std::fabs(s.rhs_row[r])) << "row " << r;
    }
    EXPECT_GT(clamped, 0u) << "no row reached the bounds: the test does not see them";
    EXPECT_LT(narrowest, widest) << "every row scaled alike: the test shows nothing";
    // The by-column copy follows the rows: the solve agrees with a dense solve of the scaled rows,
    // and differs from the unscaled solution.
    const std::vector<double> exact = dense_solution(scaled);
    std::vector<double> again;
    solve_least_squares(scaled, again);
    double moved = 0.0;
    for (uint32_t c = 0; c < kColumns; ++c) {
      EXPECT_NEAR(again[c], exact[c], 2e-3) << "unknown " << c;
      moved = std::max(moved, std::fabs(exact[c] - x[c]));
    }
    EXPECT_GT(moved, 1e-3) << "the scaled rows solve as before: the test shows nothing";
  }
  SparseLeastSquares unchanged = s;  // exponent 0 leaves every row as it was
  scale_rows_by_solution(unchanged, x, 0.0, 0.25, 4.0);
  EXPECT_TRUE(unchanged.value == s.value && unchanged.rhs_row == s.rhs_row);
}

}  // namespace
}  // namespace gibake
