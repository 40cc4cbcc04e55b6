// `gibake verify --against REF --compare statistical` (see bake_verify.h): two Monte Carlo bakes of
// the same scene and settings (another backend, another seed) agree within their noise, not value
// for value: a ray that hits on one and escapes on the other moves one depth texel by the scene's
// size. So each quantity is judged by how many probes or texels lie beyond a bound, and the bounds
// of the irradiance come from the noise the probes report of themselves (their relative_error).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "io/bakefile/bake_verify.h"

namespace gibake::verify_detail {
namespace {

using nlohmann::json;

// How much noisier than its mean irradiance a probe's irradiance is in one direction (the SH read
// over the 64 directions, their worst taken) and in one atlas texel (a cosine lobe over a
// hemisphere: about half the rays): the probe's relative_error measures its mean.
constexpr double kDirectionalNoise = 2.0;
constexpr double kTexelNoise = 3.0;
// A probe's relocation offset counts as beyond when the two bakes moved it this far apart (cells).
constexpr double kOffsetCells = 0.1;

double luminance(const loader::Rgb& e) { return 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]; }
double luminance4(const std::array<float, 4>& t) { return 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2]; }

// The share of items beyond their bound, judged against the allowed fraction; the worst item named.
struct Beyond {
  uint64_t items = 0, beyond = 0;
  double worst = 0.0;  // largest score (difference / bound); > 1 is beyond
  int64_t worst_item = -1;
  std::vector<float> scores;  // for the quantiles
  void add(double score, int64_t item) {
    if (std::isnan(score)) score = std::numeric_limits<double>::infinity();
    ++items;
    beyond += score > 1.0;
    scores.push_back(float(std::min(score, 1e30)));
    if (score > worst) {
      worst = score;
      worst_item = item;
    }
  }
  double fraction() const { return items ? double(beyond) / double(items) : 0.0; }
  double quantile(double q) {
    if (scores.empty()) return 0.0;
    const size_t k = std::min(scores.size() - 1, size_t(q * double(scores.size())));
    std::nth_element(scores.begin(), scores.begin() + std::ptrdiff_t(k), scores.end());
    return scores[k];
  }
};

void judge_beyond(VerifyReport& report, const std::string& name, Beyond& s, double max_fraction,
                  const std::string& item_label, const std::string& bound) {
  const bool ok = s.fraction() <= max_fraction;
  json details{{"items", s.items},          {"beyond", s.beyond},         {"fraction_beyond", s.fraction()},
               {"max_fraction", max_fraction}, {"worst_score", s.worst},   {"score_median", s.quantile(0.5)},
               {"score_p99", s.quantile(0.99)}, {"bound", bound}};
  details["worst_" + item_label] = s.worst_item;
  char line[256];
  std::snprintf(line, sizeof line, "%llu of %llu %ss (%.3g%%) beyond %s (allowed %.3g%%); worst %s %lld at %.3g x",
                static_cast<unsigned long long>(s.beyond), static_cast<unsigned long long>(s.items),
                item_label.c_str(), 100.0 * s.fraction(), bound.c_str(), 100.0 * max_fraction, item_label.c_str(),
                static_cast<long long>(s.worst_item), s.worst);
  add(report, name, ok ? "pass" : "fail", line, details);
}

// One probe's irradiance in luminance over the fixed directions, its mean, and its standard error
// (relative_error x mean: the noise of the probe's mean ray luminance, which the bake measured).
struct ProbeLight {
  std::vector<double> e;
  double mean = 0.0, sigma = 0.0;
};
ProbeLight probe_light(const loader::DdgiVolume& v, uint32_t p) {
  ProbeLight out;
  for (const loader::Vec3& n : directions()) out.e.push_back(luminance(sh_irradiance_raw(v, p, n)));
  for (double x : out.e) out.mean += x;
  out.mean /= double(out.e.size());
  out.sigma = std::fabs(out.mean) * std::max(0.f, v.stats(p).relative_error);
  return out;
}

struct VolumeNoise {
  std::vector<double> sigma;  // per probe: the combined noise of the pair (lux, luminance); < 0 not compared
  double floor = 0.0;         // a noise floor: float rounding of the volume's mean light
};

// Probes: states, the irradiance of each probe against the pair's noise, the pair's overall bias.
VolumeNoise compare_probes(const loader::DdgiVolume& a, const loader::DdgiVolume& b, const std::string& prefix,
                           const StatisticalOptions& o, VerifyReport& report) {
  const uint32_t n = a.probe_count();
  std::vector<ProbeLight> la(n), lb(n);
  std::vector<char> compared(n, 0);
  uint64_t state_mismatches = 0, both_active = 0;
  int64_t first_state = -1;
  double volume_light = 0.0;
  for (uint32_t p = 0; p < n; ++p) {
    if (a.state(p) != b.state(p)) {
      if (state_mismatches++ == 0) first_state = p;
      continue;
    }
    if (a.state(p) == GIBAKE_PROBE_INACTIVE) continue;
    compared[p] = 1;
    ++both_active;
    la[p] = probe_light(a, p);
    lb[p] = probe_light(b, p);
    volume_light += std::fabs(lb[p].mean);
  }
  VolumeNoise noise;
  noise.sigma.assign(n, -1.0);
  noise.floor = 1e-5 * (both_active ? volume_light / double(both_active) : 0.0) + 1e-30;
  const double state_fraction = n ? double(state_mismatches) / double(n) : 0.0;
  json sd{{"mismatches", state_mismatches}, {"probes", n}, {"fraction_beyond", state_fraction},
          {"max_fraction", o.max_fraction}, {"worst_probe", first_state}};
  char line[200];
  std::snprintf(line, sizeof line, "%llu of %u probe states differ (%.3g%%, allowed %.3g%%)%s",
                static_cast<unsigned long long>(state_mismatches), n, 100.0 * state_fraction, 100.0 * o.max_fraction,
                state_mismatches ? (", first probe " + std::to_string(first_state)).c_str() : "");
  add(report, prefix + "states", state_fraction <= o.max_fraction ? "pass" : "fail", line, sd);

  Beyond sh;
  double sum_diff = 0.0, sum_ref = 0.0, sum_var = 0.0;
  for (uint32_t p = 0; p < n; ++p) {
    if (!compared[p]) continue;
    const double sigma = std::hypot(la[p].sigma, lb[p].sigma) + noise.floor;
    noise.sigma[p] = sigma;
    double worst = 0.0;
    for (size_t d = 0; d < la[p].e.size(); ++d) worst = std::max(worst, std::fabs(la[p].e[d] - lb[p].e[d]));
    sh.add(worst / (o.sigmas * kDirectionalNoise * sigma), p);
    sum_diff += la[p].mean - lb[p].mean;
    sum_ref += lb[p].mean;
    sum_var += sigma * sigma;
  }
  char bound[96];
  std::snprintf(bound, sizeof bound, "%.3g x %.3g x the pair's noise", o.sigmas, kDirectionalNoise);
  judge_beyond(report, prefix + "sh_irradiance", sh, o.max_fraction, "probe", bound);

  // The mean irradiance over every compared probe: independent noise averages out, a wrong bake's
  // systematic difference does not.
  const double bias = sum_ref > 0.0 ? sum_diff / sum_ref : 0.0;
  const double bias_sigma = sum_ref > 0.0 ? std::sqrt(sum_var) / sum_ref : 0.0;
  const double allowed = std::max(o.sigmas * bias_sigma, o.bias_floor);
  const bool bias_ok = std::fabs(bias) <= allowed;
  std::snprintf(line, sizeof line,
                "mean irradiance %+.3g%% against the reference (allowed +-%.3g%%: %.3g x its noise %.3g%%, at least "
                "%.3g%%)",
                100.0 * bias, 100.0 * allowed, o.sigmas, 100.0 * bias_sigma, 100.0 * o.bias_floor);
  add(report, prefix + "irradiance_bias", bias_ok ? "pass" : "fail", line,
      {{"bias", bias}, {"bias_noise", bias_sigma}, {"allowed", allowed}, {"probes", both_active}});

  Beyond offsets;
  const float* spacing = a.desc().spacing;
  const double cell = std::max(1e-6, double(std::min({spacing[0], spacing[1], spacing[2]})));
  for (uint32_t p = 0; p < n; ++p) {
    if (a.state(p) != b.state(p)) continue;
    const loader::Vec3 oa = a.offset(p), ob = b.offset(p);
    const double d = std::sqrt(double(oa[0] - ob[0]) * (oa[0] - ob[0]) + double(oa[1] - ob[1]) * (oa[1] - ob[1]) +
                               double(oa[2] - ob[2]) * (oa[2] - ob[2]));
    offsets.add(d / (kOffsetCells * cell), p);
  }
  std::snprintf(bound, sizeof bound, "%.3g of the probe spacing (%.3g m)", kOffsetCells, cell);
  judge_beyond(report, prefix + "offsets", offsets, o.max_fraction, "probe", bound);
  return noise;
}

// Atlases, texel by texel, each texel judged against its probe's noise (irradiance) or the probe
// spacing (depth), as a share of the texels.
void compare_atlases(const loader::DdgiVolume& a, const loader::DdgiVolume& b, const VolumeNoise& noise,
                     const std::string& prefix, const StatisticalOptions& o, VerifyReport& report) {
  const gibake_ddgi_volume &da = a.desc(), &db = b.desc();
  const uint32_t border = da.tile_border;
  const float* spacing = da.spacing;
  const double cell = std::max(1e-6, double(std::min({spacing[0], spacing[1], spacing[2]})));
  if (a.has_irradiance() != b.has_irradiance() || da.irradiance_width != db.irradiance_width ||
      da.irradiance_height != db.irradiance_height) {
    add(report, prefix + "irradiance_atlas", "fail", "irradiance atlas presence or size differs");
  } else if (a.has_irradiance()) {
    Beyond s;
    const uint32_t side = da.irradiance_tile + 2 * border;
    for (uint32_t p = 0; p < a.probe_count(); ++p) {
      if (noise.sigma[p] < 0.0) continue;
      const std::array<uint32_t, 2> t = a.tile_origin(p, da.irradiance_tile);
      for (uint32_t y = t[1]; y < t[1] + side; ++y)
        for (uint32_t x = t[0]; x < t[0] + side; ++x) {
          const double d = std::fabs(luminance4(a.irradiance_texel(x, y)) - luminance4(b.irradiance_texel(x, y)));
          s.add(d / (o.sigmas * kTexelNoise * noise.sigma[p]), int64_t(y) * da.irradiance_width + x);
        }
    }
    char bound[96];
    std::snprintf(bound, sizeof bound, "%.3g x %.3g x the probe pair's noise", o.sigmas, kTexelNoise);
    judge_beyond(report, prefix + "irradiance_atlas", s, o.max_fraction, "texel", bound);
  }
  if (a.has_depth() != b.has_depth() || da.depth_width != db.depth_width || da.depth_height != db.depth_height) {
    add(report, prefix + "depth_atlas", "fail", "depth atlas presence or size differs");
  } else if (a.has_depth()) {
    Beyond s;
    const uint32_t side = da.depth_tile + 2 * border;
    for (uint32_t p = 0; p < a.probe_count(); ++p) {
      if (a.state(p) != b.state(p)) continue;
      const std::array<uint32_t, 2> t = a.tile_origin(p, da.depth_tile);
      for (uint32_t y = t[1]; y < t[1] + side; ++y)
        for (uint32_t x = t[0]; x < t[0] + side; ++x) {
          const double ra = a.depth_texel(x, y)[0], rb = b.depth_texel(x, y)[0];
          s.add(std::fabs(ra - rb) / (o.depth * std::max(cell, std::fabs(rb))), int64_t(y) * da.depth_width + x);
        }
    }
    char bound[96];
    std::snprintf(bound, sizeof bound, "%.3g of max(mean distance, probe spacing)", o.depth);
    judge_beyond(report, prefix + "depth_atlas", s, o.max_fraction, "texel", bound);
  }
}

}  // namespace

void compare_volume_statistical(const loader::DdgiVolume& a, const loader::DdgiVolume& b, const std::string& prefix,
                                const StatisticalOptions& o, VerifyReport& report) {
  if (!a.has_stats() || !b.has_stats()) {
    add(report, prefix + "statistics", "fail",
        std::string(!a.has_stats() ? "the file" : "the reference") +
            " has no probe statistics (relative_error): its noise is unknown; compare with --compare values");
    return;
  }
  const VolumeNoise noise = compare_probes(a, b, prefix, o, report);
  compare_atlases(a, b, noise, prefix, o, report);
}

}  // namespace gibake::verify_detail
