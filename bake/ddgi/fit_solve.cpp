// The surface fit's least-squares solve (fit_solve.h).
#include "bake/ddgi/fit_solve.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace gibake {

namespace {

constexpr size_t kChunk = 8192;  // rows or columns a task; sums reduced chunk by chunk in order
// Rows or columns a task where each is computed on its own (no sum across them): fine enough that
// columns of very different lengths spread evenly over the threads; it changes no result.
constexpr size_t kGrain = 512;

// Runs visit(i, sum, largest) over [0, n) in fixed chunks, in parallel; returns the chunks' sums
// added in chunk order (the same double whatever the thread count) and the largest of `largest`.
struct Reduced {
  double sum = 0.0, largest = 0.0;
};

template <class Visit>
Reduced chunked(size_t n, const Visit& visit) {
  const size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<Reduced> partial(chunks);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    Reduced part;
    for (size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) visit(i, part.sum, part.largest);
    partial[c] = part;
  });
  Reduced all;
  for (const Reduced& part : partial) all.sum += part.sum, all.largest = std::max(all.largest, part.largest);
  return all;
}

double ordered_dot(const std::vector<double>& a, const std::vector<double>& b) {
  return chunked(a.size(), [&](size_t i, double& sum, double&) { sum += a[i] * b[i]; }).sum;
}

// The groups' columns, group by group in column order, and each group's whole pull: its columns'
// priors and its own.
struct Groups {
  std::vector<size_t> start;
  std::vector<uint32_t> member;
  std::vector<double> pull;
};

Groups index_groups(const SparseLeastSquares& sys) {
  Groups g;
  const size_t G = sys.group_prior.size();
  g.start.assign(G + 1, 0);
  g.pull = sys.group_prior;
  for (size_t c = 0; c < sys.group.size(); ++c)
    if (sys.group[c] >= 0) ++g.start[size_t(sys.group[c]) + 1], g.pull[size_t(sys.group[c])] += sys.prior[c];
  for (size_t k = 0; k < G; ++k) g.start[k + 1] += g.start[k];
  g.member.resize(g.start[G]);
  std::vector<size_t> next(g.start.begin(), g.start.end() - 1);
  for (size_t c = 0; c < sys.group.size(); ++c)
    if (sys.group[c] >= 0) g.member[next[size_t(sys.group[c])]++] = uint32_t(c);
  return g;
}

// Each group's prior-weighted sum of its columns over its whole pull: the part of its best value
// that depends on x.
void group_means(const SparseLeastSquares& sys, const Groups& groups, const std::vector<double>& x,
                 std::vector<double>& out) {
  const size_t G = sys.group_prior.size();
  out.resize(G);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, G, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t g = range.begin(); g < range.end(); ++g) {
      double s = 0.0;
      for (size_t k = groups.start[g]; k < groups.start[g + 1]; ++k)
        s += sys.prior[groups.member[k]] * x[groups.member[k]];
      out[g] = groups.pull[g] > 0.0 ? s / groups.pull[g] : 0.0;  // no pull at all: no prior term either
    }
  });
}

// out = (A^T A + P) x, P the priors with the group values eliminated: prior_c (x_c - mean_g(x)) for
// a grouped column.
void apply_normal(const SparseLeastSquares& sys, const Groups& groups, const std::vector<double>& x,
                  std::vector<double>& rows, std::vector<double>& means, std::vector<double>& out) {
  const size_t R = sys.rhs_row.size(), C = sys.prior.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, R, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t r = range.begin(); r < range.end(); ++r) {
      double s = 0.0;
      for (size_t k = sys.row_start[r]; k < sys.row_start[r + 1]; ++k) s += double(sys.value[k]) * x[sys.column[k]];
      rows[r] = s;
    }
  });
  group_means(sys, groups, x, means);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, C, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t c = range.begin(); c < range.end(); ++c) {
      const int32_t g = sys.group.empty() ? -1 : sys.group[c];
      double s = sys.prior[c] * (g >= 0 ? x[c] - means[size_t(g)] : x[c]);
      for (size_t k = sys.col_start[c]; k < sys.col_start[c + 1]; ++k)
        s += double(sys.col_value[k]) * rows[sys.col_row[k]];
      out[c] = s;
    }
  });
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
  const Groups groups = index_groups(sys);
  std::vector<double> b(C, 0.0), rows(R), means, r(C), p(C), q(C), inverse_diagonal(C), z(C);
  x.resize(C);
  chunked(C, [&](size_t c, double&, double&) {  // A^T t plus the priors' pull, and the diagonal, rows in order
    const int32_t g = sys.group.empty() ? -1 : sys.group[c];
    double s = 0.0, diagonal = sys.prior[c], row_sum = 0.0;
    if (g >= 0) {
      const double pull = groups.pull[size_t(g)];
      if (pull > 0.0) {
        s = sys.prior[c] * sys.group_prior[size_t(g)] * sys.group_target[size_t(g)] / pull;
        diagonal -= sys.prior[c] * sys.prior[c] / pull;
      }
      x[c] = sys.group_target[size_t(g)];
    } else {
      s = sys.prior[c] * sys.target[c];
      x[c] = sys.target[c];
    }
    // A row may hold a column more than once: the diagonal squares each row's sum, the entries of
    // one row lying side by side.
    for (size_t k = sys.col_start[c]; k < sys.col_start[c + 1]; ++k) {
      s += double(sys.col_value[k]) * sys.rhs_row[sys.col_row[k]];
      if (k > sys.col_start[c] && sys.col_row[k] != sys.col_row[k - 1]) diagonal += row_sum * row_sum, row_sum = 0.0;
      row_sum += double(sys.col_value[k]);
    }
    diagonal += row_sum * row_sum;
    b[c] = s;
    inverse_diagonal[c] = diagonal > 0.0 ? 1.0 / diagonal : 1.0;
  });
  apply_normal(sys, groups, x, rows, means, q);
  // z: the Jacobi steps; `step` the largest, rz = r . z.
  Reduced reduced = chunked(C, [&](size_t c, double& rz, double& step) {
    r[c] = b[c] - q[c];
    z[c] = inverse_diagonal[c] * r[c];
    p[c] = z[c];
    rz += r[c] * z[c];
    step = std::max(step, std::fabs(z[c]));
  });
  int it = 0;
  for (; it < kFitSolveMaxIterations && reduced.largest > kFitSolveTolerance; ++it) {
    apply_normal(sys, groups, p, rows, means, q);
    const double pq = ordered_dot(p, q);
    if (!(pq > 0.0)) break;
    const double alpha = reduced.sum / pq;
    const Reduced next = chunked(C, [&](size_t c, double& rz, double& step) {
      x[c] += alpha * p[c];
      r[c] -= alpha * q[c];
      z[c] = inverse_diagonal[c] * r[c];
      rz += r[c] * z[c];
      step = std::max(step, std::fabs(z[c]));
    });
    const double beta = next.sum / reduced.sum;
    reduced = next;
    chunked(C, [&](size_t c, double&, double&) { p[c] = z[c] + beta * p[c]; });
  }
  return it;
}

std::vector<double> group_values(const SparseLeastSquares& sys, const std::vector<double>& x) {
  const Groups groups = index_groups(sys);
  std::vector<double> means;
  group_means(sys, groups, x, means);
  for (size_t g = 0; g < means.size(); ++g)
    means[g] = groups.pull[g] > 0.0 ? means[g] + sys.group_prior[g] * sys.group_target[g] / groups.pull[g]
                                    : sys.group_target[g];  // nothing pulls it: its target
  return means;
}

void scale_rows_by_solution(SparseLeastSquares& sys, const std::vector<double>& x, double exponent, double min_ratio,
                            double max_ratio) {
  const size_t rows = sys.rhs_row.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rows, 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t r = range.begin(); r < range.end(); ++r) {
      double solved = 0.0, before = 0.0;
      for (size_t k = sys.row_start[r]; k < sys.row_start[r + 1]; ++k) {
        solved += double(sys.value[k]) * x[sys.column[k]];
        before += double(sys.value[k]);
      }
      const double ratio =
          before > 0.0 && std::isfinite(solved) ? std::clamp(solved / before, min_ratio, max_ratio) : 1.0;
      const double scale = std::pow(ratio, -exponent);
      for (size_t k = sys.row_start[r]; k < sys.row_start[r + 1]; ++k)
        sys.value[k] = float(double(sys.value[k]) * scale);
      sys.rhs_row[r] *= scale;
    }
  });
  index_columns(sys, sys.prior.size());
}

}  // namespace gibake
