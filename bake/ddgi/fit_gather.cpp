// The fit's truth from its paths (fit_gather.h).
#include "bake/ddgi/fit_gather.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace gibake {

namespace {

using Region = std::array<int64_t, 4>;

// A region's side in its volume's spacings: wide enough that R's noise is small (its points' whole
// paths pooled), narrow enough to follow the probes' errors where they change (a house's rooms
// against the sunlit ground around it; docs/BENCHMARKS.md "The fit's gather").
constexpr double kRegionSpacings = 4.0;

// Squared standard error of a mean from its two halves' means (they differ by about twice it).
double half_variance(double a, double b) { return 0.25 * (a - b) * (a - b); }

// A point whose estimates are all numbers; one that is not (a path gone wrong) stays out of every
// sum, so that it costs only its own sample (the fit leaves out a truth that is not a number).
bool finite(const FitPointLight& l) {
  return std::isfinite(l.f) && std::isfinite(l.g) && std::isfinite(l.f_half[0]) && std::isfinite(l.f_half[1]) &&
         std::isfinite(l.g_half[0]) && std::isfinite(l.g_half[1]);
}

struct RegionRatio {
  double ratio = 1.0, noise = 0.0;  // R and its relative variance
  double bias = 0.0;                // the region's points' bias of R g (bias_beyond_noise)
};

// The relative squared bias that squared differences `diff2` hold beyond their noise `var` and
// beyond the spread of that estimate (the difference of two sums each varying by about
// sqrt(2 sum v^2), `var2` = sum v^2): with few points, noise alone would otherwise read as bias
// about as large as f's own error. Relative to `squares`, the squared values of R g.
double bias_beyond_noise(double diff2, double var, double var2, double squares) {
  return squares > 0.0 ? std::max(0.0, diff2 - var - 2.0 * std::sqrt(var2)) / squares : 0.0;
}

// One probe's points [first, last), f alone: relative variance pooled over them (their squared
// standard errors over their squared values, summed: one point's two halves say little about its
// noise, the few points of one probe together say enough).
void whole_truths(const std::vector<FitPointLight>& p, size_t first, size_t last, std::vector<FitTruth>& out) {
  double variance = 0.0, squares = 0.0;
  for (size_t i = first; i < last; ++i) {
    if (!finite(p[i])) continue;
    variance += half_variance(p[i].f_half[0], p[i].f_half[1]);
    squares += p[i].f * p[i].f;
  }
  const double noise = squares > 0.0 ? variance / squares : 0.0;
  for (size_t i = first; i < last; ++i) out[i] = FitTruth{p[i].f, noise};
}

// Sums over points [first, last) of k g against f, for a ratio k: the variance of k g and its
// squares, the variances of f - k g (and their squares) and its squared differences.
struct RatioResiduals {
  double var_g = 0.0, squares = 0.0, var = 0.0, var2 = 0.0, diff2 = 0.0;
  double bias() const { return bias_beyond_noise(diff2, var, var2, squares); }
};

RatioResiduals ratio_residuals(const std::vector<FitPointLight>& p, size_t first, size_t last, double k) {
  RatioResiduals s;
  for (size_t i = first; i < last; ++i) {
    const FitPointLight& l = p[i];
    if (!finite(l)) continue;
    s.var_g += k * k * half_variance(l.g_half[0], l.g_half[1]);
    s.squares += k * k * l.g * l.g;
    const double v = half_variance(l.f_half[0] - k * l.g_half[0], l.f_half[1] - k * l.g_half[1]);
    s.var += v;
    s.var2 += v * v;
    s.diff2 += (l.f - k * l.g) * (l.f - k * l.g);
  }
  return s;
}

// A probe's own ratio rho = sum f / sum g over its points, and the expected squared relative error
// of rho g there: g's noise, the whole paths' pooled over the probe's points, and the bias rho
// leaves (the probe's ended light wrong by other than one factor). `valid` false: no light in one
// of the gathers.
struct ProbeRatio {
  bool valid = false;
  double ratio = 0.0, error = 0.0;
};

ProbeRatio probe_ratio(const std::vector<FitPointLight>& p, size_t first, size_t last) {
  double sum_f = 0.0, sum_g = 0.0, var_f = 0.0;
  for (size_t i = first; i < last; ++i) {
    if (!finite(p[i])) continue;
    sum_f += p[i].f;
    sum_g += p[i].g;
    var_f += half_variance(p[i].f_half[0], p[i].f_half[1]);
  }
  if (!(sum_f > 0.0 && sum_g > 0.0)) return {};
  const double rho = sum_f / sum_g;
  const RatioResiduals s = ratio_residuals(p, first, last, rho);
  if (!(s.squares > 0.0)) return {};
  return {true, rho, s.var_g / s.squares + var_f / (sum_f * sum_f) + s.bias()};
}

// One probe's points, blended (the header's rule).
void blended_truths(const std::vector<FitPointLight>& p, size_t first, size_t last, const RegionRatio& region,
                    bool own_ratio, std::vector<FitTruth>& out) {
  const double r = region.ratio;
  double var_f = 0.0, sq_f = 0.0;
  for (size_t i = first; i < last; ++i) {
    if (!finite(p[i])) continue;
    var_f += half_variance(p[i].f_half[0], p[i].f_half[1]);
    sq_f += p[i].f * p[i].f;
  }
  const RatioResiduals rg = ratio_residuals(p, first, last, r);
  if (!(rg.squares > 0.0)) return whole_truths(p, first, last, out);
  const double error_f = sq_f > 0.0 ? var_f / sq_f : 0.0;
  // The bias R leaves at this probe's points, or over its region's, whichever is larger: a probe has
  // few points (a handful where the probes are dense), too few to tell bias from noise alone.
  const double error_g = rg.var_g / rg.squares + region.noise + std::max(rg.bias(), region.bias);
  // The probe's own estimate: rho g where its ended light is wrong by one factor (each point then
  // without its own whole paths' noise), f where not.
  const ProbeRatio own = own_ratio ? probe_ratio(p, first, last) : ProbeRatio{};
  const double v = own.valid && own.error + error_f > 0.0 ? error_f / (own.error + error_f) : 0.0;  // of rho g
  const double error_own = v * v * own.error + (1.0 - v) * (1.0 - v) * error_f;
  // R g is weighed against the whole paths' error, not the probe's own estimate's: that one's bias
  // is judged from a probe's few points, leniently, and understates it.
  const double w = error_g + error_f > 0.0 ? error_f / (error_g + error_f) : 1.0;  // of R g
  const double noise = w * w * error_g + (1.0 - w) * (1.0 - w) * error_own;
  const double scale = w * r + (1.0 - w) * v * own.ratio;
  for (size_t i = first; i < last; ++i) out[i] = FitTruth{scale * p[i].g + (1.0 - w) * (1.0 - v) * p[i].f, noise};
}

// Every region's R, its relative variance (the summed variances of f - R g over its f squared) and
// the bias R leaves over its points.
std::map<Region, RegionRatio> region_ratios(const std::vector<FitPointLight>& p) {
  struct Sums {
    double f = 0.0, g = 0.0;                               // first pass
    double var = 0.0, var2 = 0.0, diff2 = 0.0, rg2 = 0.0;  // of f - R g, and (R g)^2
  };
  std::map<Region, Sums> sums;
  for (const FitPointLight& l : p) {
    if (!finite(l)) continue;
    Sums& s = sums[l.region];
    s.f += l.f;
    s.g += l.g;
  }
  for (const FitPointLight& l : p) {
    if (!finite(l)) continue;
    Sums& s = sums[l.region];
    const double r = s.g > 0.0 ? s.f / s.g : 1.0;
    const double v = half_variance(l.f_half[0] - r * l.g_half[0], l.f_half[1] - r * l.g_half[1]);
    s.var += v;
    s.var2 += v * v;
    s.diff2 += (l.f - r * l.g) * (l.f - r * l.g);
    s.rg2 += r * r * l.g * l.g;
  }
  std::map<Region, RegionRatio> out;
  for (const auto& [key, s] : sums)
    if (s.f > 0.0 && s.g > 0.0)
      out[key] = RegionRatio{s.f / s.g, s.var / (s.f * s.f), bias_beyond_noise(s.diff2, s.var, s.var2, s.rg2)};
  return out;
}

}  // namespace

std::vector<FitTruth> fit_truths(const std::vector<FitPointLight>& p, bool both, bool own_ratio) {
  const std::map<Region, RegionRatio> regions = both ? region_ratios(p) : std::map<Region, RegionRatio>{};
  std::vector<FitTruth> out(p.size());
  size_t first = 0;
  while (first < p.size()) {
    size_t last = first;
    while (last < p.size() && p[last].probe == p[first].probe) ++last;
    // A region without light in one of its gathers (a dark corner, g all zero) has no ratio: f.
    const auto region = regions.find(p[first].region);
    if (region != regions.end())
      blended_truths(p, first, last, region->second, own_ratio, out);
    else
      whole_truths(p, first, last, out);
    first = last;
  }
  return out;
}

std::array<int64_t, 4> fit_region(uint32_t volume, const float position[3], float spacing) {
  const double cell = kRegionSpacings * (spacing > 0.f ? double(spacing) : 1.0);
  return {int64_t(volume), int64_t(std::floor(position[0] / cell)), int64_t(std::floor(position[1] / cell)),
          int64_t(std::floor(position[2] / cell))};
}

}  // namespace gibake
