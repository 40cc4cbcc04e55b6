// `gibake verify --against REF --compare statistical` (see bake_verify.h): two Monte Carlo bakes of
// the same scene and settings (another backend, another seed) agree within their noise, not value
// for value: a ray that hits on one and escapes on the other moves one depth texel by the scene's
// size. So each quantity is judged by how many probes or texels lie beyond a bound, and the bounds
// of the irradiance come from the noise the probes report of themselves (their relative_error).
#include <algorithm>
#include <array>
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
// The rays a depth texel's mean stands for, as a share of its probe's rays: the texel weighs them
// by cos^64 of their angle to its direction (kernels/integrate.h), whose effective count
// (sum w)^2 / sum w^2 is N (2p + 1) / (2 (p + 1)^2) for N rays over the sphere, p = 64.
constexpr double kDepthRayShare = 129.0 / (2.0 * 65.0 * 65.0);
// A mean irradiance allowed to differ by more than this share is no check: a pair that noisy
// cannot tell a bake of twice the light from a right one, and says so instead of passing.
constexpr double kMostBiasAllowed = 0.5;

// The side of a probe cell: the smallest spacing of the axes with more than one probe (a flat grid
// has spacing 0 on its single-probe axis), else the volume's reach.
double probe_cell(const gibake_ddgi_volume& d) {
  double cell = 0.0;
  for (int a = 0; a < 3; ++a)
    if (d.counts[a] > 1 && d.spacing[a] > 0.f) cell = cell > 0.0 ? std::min(cell, double(d.spacing[a])) : d.spacing[a];
  if (cell > 0.0) return cell;
  return d.max_distance > 0.f ? double(d.max_distance) : 1.0;
}

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

// At most `max_fraction` of `items` may lie beyond, rounded up to a whole item: in a volume of a
// few dozen probes one probe is already more than the fraction, and one outlier of the noise is
// what a right pair shows there.
uint64_t allowed_items(double max_fraction, uint64_t items) {
  return uint64_t(std::ceil(max_fraction * double(items) - 1e-9));
}

void judge_beyond(VerifyReport& report, const std::string& name, Beyond& s, double max_fraction,
                  const std::string& item_label, const std::string& bound) {
  const bool ok = s.beyond <= allowed_items(max_fraction, s.items);
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

// One probe's irradiance in luminance over the fixed directions, its mean (and each channel's), and
// its standard error (relative_error x mean: the noise of the probe's mean ray luminance, which the
// bake measured).
struct ProbeLight {
  std::vector<double> e;
  double mean = 0.0, sigma = 0.0, relative = 0.0;
  std::array<double, 3> rgb{0.0, 0.0, 0.0};
};
ProbeLight probe_light(const loader::DdgiVolume& v, uint32_t p) {
  ProbeLight out;
  for (const loader::Vec3& n : directions()) {
    const loader::Rgb e = sh_irradiance_raw(v, p, n);
    out.e.push_back(luminance(e));
    for (size_t c = 0; c < 3; ++c) out.rgb[c] += e[c] / double(directions().size());
  }
  for (double x : out.e) out.mean += x;
  out.mean /= double(out.e.size());
  out.relative = std::max(0.f, v.stats(p).relative_error);
  out.sigma = std::fabs(out.mean) * out.relative;
  return out;
}

// The mean irradiance over the compared probes, luminance and each channel: a's difference from b
// relative to b's, and the noise of that ratio from the probes' own (channels: each probe's
// relative error of its luminance read as the channel's).
struct Bias {
  double diff = 0.0, ref = 0.0, var = 0.0;
  void add(double a, double b, double sigma) {
    diff += a - b;
    ref += b;
    var += sigma * sigma;
  }
  double value() const { return ref > 0.0 ? diff / ref : 0.0; }
  double noise() const { return ref > 0.0 ? std::sqrt(var) / ref : 0.0; }
};

// Judges the pair's mean irradiance: independent noise averages out over the probes, a wrong
// bake's systematic difference does not. Each channel too, so that light of another colour at the
// same luminance is seen.
void judge_bias(const Bias& lum, const std::array<Bias, 3>& rgb, uint64_t probes, const std::string& name,
                const StatisticalOptions& o, VerifyReport& report) {
  const auto allowed_for = [&](const Bias& b) { return std::max(o.sigmas * b.noise(), o.bias_floor); };
  const Bias* worst = &lum;
  const char* which = "";
  for (size_t c = 0; c < 3; ++c)
    if (std::fabs(rgb[c].value()) / allowed_for(rgb[c]) > std::fabs(worst->value()) / allowed_for(*worst)) {
      worst = &rgb[c];
      which = c == 0 ? " (red)" : c == 1 ? " (green)" : " (blue)";
    }
  const double allowed = allowed_for(*worst);
  char line[320];
  std::snprintf(line, sizeof line,
                "mean irradiance%s %+.3g%% against the reference (allowed +-%.3g%%: %.3g x its noise %.3g%%, at least "
                "%.3g%%)",
                which, 100.0 * worst->value(), 100.0 * allowed, o.sigmas, 100.0 * worst->noise(), 100.0 * o.bias_floor);
  json details{{"bias", lum.value()}, {"bias_noise", lum.noise()}, {"allowed", allowed_for(lum)}, {"probes", probes}};
  for (size_t c = 0; c < 3; ++c) details["bias_rgb"].push_back(rgb[c].value());
  if (std::fabs(worst->value()) > allowed) {
    add(report, name, "fail", line, details);
  } else if (allowed_for(lum) > kMostBiasAllowed) {
    std::snprintf(line, sizeof line,
                  "not judged: the pair's noise allows the mean irradiance +-%.3g%% (it differs %+.3g%%), too noisy "
                  "to tell a wrong bake; bake both with more rays (--quality default, --ray-budget)",
                  100.0 * allowed_for(lum), 100.0 * lum.value());
    add(report, name, "skip", line, details);
  } else {
    add(report, name, "pass", line, details);
  }
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
  add(report, prefix + "states", state_mismatches <= allowed_items(o.max_fraction, n) ? "pass" : "fail", line, sd);

  Beyond sh;
  Bias lum;
  std::array<Bias, 3> rgb;
  for (uint32_t p = 0; p < n; ++p) {
    if (!compared[p]) continue;
    const double sigma = std::hypot(la[p].sigma, lb[p].sigma) + noise.floor;
    noise.sigma[p] = sigma;
    double worst = 0.0;
    for (size_t d = 0; d < la[p].e.size(); ++d) worst = std::max(worst, std::fabs(la[p].e[d] - lb[p].e[d]));
    sh.add(worst / (o.sigmas * kDirectionalNoise * sigma), p);
    lum.add(la[p].mean, lb[p].mean, sigma);
    for (size_t c = 0; c < 3; ++c)
      rgb[c].add(la[p].rgb[c], lb[p].rgb[c],
                 std::hypot(la[p].rgb[c] * la[p].relative, lb[p].rgb[c] * lb[p].relative) + noise.floor);
  }
  char bound[96];
  std::snprintf(bound, sizeof bound, "%.3g x %.3g x the pair's noise", o.sigmas, kDirectionalNoise);
  judge_beyond(report, prefix + "sh_irradiance", sh, o.max_fraction, "probe", bound);
  judge_bias(lum, rgb, both_active, prefix + "irradiance_bias", o, report);

  Beyond offsets;
  const double cell = probe_cell(a.desc());
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
  const double cell = probe_cell(da);
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
    // A texel's mean distance is noisy where its rays both hit and escape (the horizon of an open
    // scene): its own spread (the moments' variance) over the rays it stands for bounds the pair's
    // difference too, whichever bound is wider.
    Beyond s;
    const uint32_t side = da.depth_tile + 2 * border;
    for (uint32_t p = 0; p < a.probe_count(); ++p) {
      if (a.state(p) != b.state(p)) continue;
      const double rays = std::max(1.0, kDepthRayShare * double(std::min(a.stats(p).rays, b.stats(p).rays)));
      const std::array<uint32_t, 2> t = a.tile_origin(p, da.depth_tile);
      for (uint32_t y = t[1]; y < t[1] + side; ++y)
        for (uint32_t x = t[0]; x < t[0] + side; ++x) {
          const auto ta = a.depth_texel(x, y), tb = b.depth_texel(x, y);
          const double ra = ta[0], rb = tb[0];
          const double spread = std::max(0.0, double(ta[1]) - ra * ra) + std::max(0.0, double(tb[1]) - rb * rb);
          const double bound = std::max(o.depth * std::max(cell, std::fabs(rb)), o.sigmas * std::sqrt(spread / rays));
          s.add(std::fabs(ra - rb) / bound, int64_t(y) * da.depth_width + x);
        }
    }
    char bound[128];
    std::snprintf(bound, sizeof bound, "%.3g of max(mean distance, probe spacing) or %.3g x the texels' noise", o.depth,
                  o.sigmas);
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
