// The surface fit's least-squares solve (surface_fit.h): minimise
//   |A x - t|^2 + sum_c prior_c (x_c - target_c)^2
// over a sparse A held both by rows and by columns, where a column may instead belong to a group:
// then it is pulled towards the group's shared value y_g, which is pulled towards the group's
// target, prior_c (x_c - y_g)^2 + group_prior_g (y_g - group_target_g)^2 (the fit's texels and the
// gain of the probe tile they belong to).
//
// The group values are eliminated exactly: for given x the best y_g is the prior-weighted mean of
// its columns and its target, which leaves a quadratic in x alone whose prior couples a group's
// columns by a rank-one term. Solving for x alone keeps apart what the data cannot tell apart (a
// group's shared value and its columns' own deviations read by the same rows alike), which would
// otherwise be a near-null direction of the normal equations that only the priors hold.
//
// The columns' weights span orders of magnitude (a texel that thousands of points read beside one
// that a handful do, held mostly by its prior). Conjugate gradients on the normal equations,
// preconditioned by their diagonal (Jacobi), run until no unknown's Jacobi step (its residual over
// its diagonal, about how far it still is from the solution) exceeds kFitSolveTolerance: a stop on
// the residual's norm, which the heavy columns fill, leaves the lightly read unknowns partway to
// their solution, and where they stop then moves with any change to the rows.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

namespace gibake {

// The solve's stop: no unknown's Jacobi step above it (gains: a thousandth).
constexpr double kFitSolveTolerance = 1e-3;
// Iterations at most; a solve that reaches it returns what it has.
constexpr int kFitSolveMaxIterations = 1000;

struct SparseLeastSquares {
  // CSR: row r's entries are [row_start[r], row_start[r + 1]); a column may appear more than once
  // in a row (its entries add).
  std::vector<size_t> row_start;
  std::vector<uint32_t> column;
  std::vector<float> value;
  std::vector<double> rhs_row;    // t, per row
  std::vector<size_t> col_start;  // the same entries by column, rows in order
  std::vector<uint32_t> col_row;
  std::vector<float> col_value;
  std::vector<double> prior, target;  // per column (a grouped column's target is unused)
  // Per column, its group or -1; empty when no column has one.
  std::vector<int32_t> group;
  std::vector<double> group_prior, group_target;  // per group
};

// Fills the by-column copy (col_start, col_row, col_value) from the rows, for `columns` unknowns.
void index_columns(SparseLeastSquares& system, size_t columns);

// x (per column) from the targets (a grouped column: its group's) to the solution; returns the
// iterations taken. Sums are reduced in a fixed order: the result does not depend on the thread
// count. Runs in the caller's task arena.
int solve_least_squares(const SparseLeastSquares& system, std::vector<double>& x);

// Each group's value y_g that goes with x (the prior-weighted mean of its columns and its target).
std::vector<double> group_values(const SparseLeastSquares& system, const std::vector<double>& x);

// Scales each row r (its entries and its target) by q_r^-exponent, q_r = (A x)_r / (A 1)_r: what x
// makes of the row over what it was at x = 1, held within [min_ratio, max_ratio] (1 where the row
// sums to nothing). Then refills the by-column copy. A solve after it weighs each residual by the
// solution x rather than by the values the rows were scaled to before.
void scale_rows_by_solution(SparseLeastSquares& system, const std::vector<double>& x, double exponent, double min_ratio,
                            double max_ratio);

}  // namespace gibake
