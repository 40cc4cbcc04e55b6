// The surface fit's least-squares solve (fit_solve.h).
#include "bake/ddgi/fit_solve.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace gibake {

namespace {

constexpr size_t kChunk = 8192;  // rows or columns a task; sums reduced chunk by chunk in order

double ordered_dot(const std::vector<double>& a, const std::vector<double>& b) {
  const size_t chunks = (a.size() + kChunk - 1) / kChunk;
  std::vector<double> partial(chunks, 0.0);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    double s = 0.0;
    for (size_t i = c * kChunk; i < std::min(a.size(), (c + 1) * kChunk); ++i) s += a[i] * b[i];
    partial[c] = s;
  });
  double s = 0.0;
  for (double v : partial) s += v;
  return s;
}

// out = (A^T A + diag(prior)) x
void apply_normal(const SparseLeastSquares& sys, const std::vector<double>& x, std::vector<double>& rows,
                  std::vector<double>& out) {
  const size_t R = sys.rhs_row.size(), C = sys.prior.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, R, kChunk), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t r = range.begin(); r < range.end(); ++r) {
      double s = 0.0;
      for (size_t k = sys.row_start[r]; k < sys.row_start[r + 1]; ++k) s += double(sys.value[k]) * x[sys.column[k]];
      rows[r] = s;
    }
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, C, kChunk), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t c = range.begin(); c < range.end(); ++c) {
      double s = sys.prior[c] * x[c];
      for (size_t k = sys.col_start[c]; k < sys.col_start[c + 1]; ++k)
        s += double(sys.col_value[k]) * rows[sys.col_row[k]];
      out[c] = s;
    }
  });
}

// The largest Jacobi step z (each unknown's residual over its diagonal).
double largest_step(const std::vector<double>& z) {
  double largest = 0.0;
  for (double v : z) largest = std::max(largest, std::fabs(v));
  return largest;
}

}  // namespace

void index_columns(SparseLeastSquares& sys, size_t columns) {
  sys.col_start.assign(columns + 1, 0);
  for (uint32_t c : sys.column) ++sys.col_start[c + 1];
  for (size_t c = 0; c < columns; ++c) sys.col_start[c + 1] += sys.col_start[c];
  sys.col_row.resize(sys.column.size());
  sys.col_value.resize(sys.column.size());
  std::vector<size_t> next(sys.col_start.begin(), sys.col_start.end() - 1);
  for (size_t r = 0; r + 1 < sys.row_start.size(); ++r)
    for (size_t k = sys.row_start[r]; k < sys.row_start[r + 1]; ++k) {
      const size_t at = next[sys.column[k]]++;
      sys.col_row[at] = uint32_t(r);
      sys.col_value[at] = sys.value[k];
    }
}

int solve_least_squares(const SparseLeastSquares& sys, std::vector<double>& x) {
  const size_t R = sys.rhs_row.size(), C = sys.prior.size();
  std::vector<double> b(C, 0.0), rows(R), r(C), p(C), q(C), inverse_diagonal(C), z(C);
  for (size_t c = 0; c < C; ++c) {  // A^T t + prior x target and the diagonal, rows in order
    // A row may hold a column more than once (the fit's probe gain once per texel of its tile read
    // there): the diagonal squares each row's sum, the entries of one row lying side by side.
    double s = sys.prior[c] * sys.target[c], diagonal = sys.prior[c], row_sum = 0.0;
    for (size_t k = sys.col_start[c]; k < sys.col_start[c + 1]; ++k) {
      s += double(sys.col_value[k]) * sys.rhs_row[sys.col_row[k]];
      if (k > sys.col_start[c] && sys.col_row[k] != sys.col_row[k - 1]) diagonal += row_sum * row_sum, row_sum = 0.0;
      row_sum += double(sys.col_value[k]);
    }
    diagonal += row_sum * row_sum;
    b[c] = s;
    inverse_diagonal[c] = diagonal > 0.0 ? 1.0 / diagonal : 1.0;
  }
  x = sys.target;
  apply_normal(sys, x, rows, q);
  for (size_t c = 0; c < C; ++c) {
    r[c] = b[c] - q[c];
    z[c] = inverse_diagonal[c] * r[c];
  }
  p = z;
  double rz = ordered_dot(r, z);
  int it = 0;
  for (; it < kFitSolveMaxIterations && largest_step(z) > kFitSolveTolerance; ++it) {
    apply_normal(sys, p, rows, q);
    const double pq = ordered_dot(p, q);
    if (!(pq > 0.0)) break;
    const double alpha = rz / pq;
    for (size_t c = 0; c < C; ++c) {
      x[c] += alpha * p[c];
      r[c] -= alpha * q[c];
      z[c] = inverse_diagonal[c] * r[c];
    }
    const double next = ordered_dot(r, z);
    const double beta = next / rz;
    rz = next;
    for (size_t c = 0; c < C; ++c) p[c] = z[c] + beta * p[c];
  }
  return it;
}

}  // namespace gibake
