#include "bake/ddgi/probe_filter.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bake/ddgi/probe_grid.h"
#include "kernels/octahedral.h"
#include "kernels/vec.h"

namespace gibake {
using kernels::float3;

namespace {

// Neighbours: the 26 around a probe and the probe itself, with the separable tent [1/2, 1, 1/2]^3
// as spatial weight (face 1/2, edge 1/4, corner 1/8): the smallest smooth kernel on the grid, which
// leaves a linear change across the interior as it is (its weights are symmetric).
constexpr int kTaps = 27;

using kernels::luminance;

struct FilterInput {
  const DdgiResult& r;
  kernels::AtlasLayout irr, depth;
  std::vector<float> pos;     // final probe positions, xyz
  std::vector<float> lum;     // luminance irradiance: mean over directions (DC) a, then band 1 b xyz
  std::vector<double> rel2;   // relative variance r^2 (floored)
  std::vector<uint8_t> lit;   // not inactive, with finite figures
};

// The sampler's visibility (kernels/ddgi_sample.cpp): from probe a towards a point at `dist` along
// `dir`, Chebyshev's bound on the chance that a's depth there reaches it, cubed.
float chebyshev(const FilterInput& in, int32_t a, const float3& dir, float dist) {
  if (in.r.depth_atlas.empty()) return 1.f;
  int ox, oy;
  in.depth.tile_origin(a, ox, oy);
  float m[2];
  kernels::oct_sample_bilinear(in.r.depth_atlas.data(), in.r.depth_width, 2, ox, oy, in.depth.res, dir, m);
  if (dist <= m[0]) return 1.f;
  const float variance = std::max(std::fabs(m[0] * m[0] - m[1]), 1e-4f);
  const float diff = dist - m[0];
  const float c = variance / (variance + diff * diff);
  return c * c * c;
}

// Weight of neighbour j for probe i (i itself: 1). Each probe's luminance irradiance is read as
// its mean over directions a (from L00) and its band-1 vector b (E(n) = a + b.n); r_i is the bake's
// relative standard error of the probe's mean (DdgiProbeStats), s_i = r_i a_i.
//   w_ij = t_ij * exp(-D_ij^2 / (k S_ij^2)) * V_ij
//   D_ij^2 = (a_i - a_j)^2 + |b_i - b_j|^2 / 3   (the mean of (E_i - E_j)^2 over the six axis normals)
//   S_ij^2 = (7/3) (s_i^2 + s_j^2)               (its expectation under noise alone: per-ray noise
//            puts the same variance on every SH coefficient, a gets pi^2/(4 pi) of it, each b
//            component (2 pi/3 * 0.488603)^2 = pi/3, so band 1 adds 4/3 of a's)
// - t_ij, the tent above: nearer probes hold more of the same light.
// - The bilateral factor is the noise test: with k = 4 a difference of one combined standard error
//   keeps 78% of the weight and one beyond 4 under 2%, so a change far above the noise is kept and
//   noise is averaged. A probe without noise (S = 0) takes weight only from an equal neighbour.
// - V_ij = cheb_i(j) cheb_j(i): the sampler's visibility both ways, so no light through a wall.
// There is deliberately no inverse-variance factor 1/s_j^2: s_j is estimated from the same rays as
// the value, and in long roulette paths a bright outlier raises both, so such weights favour the
// darker estimates and pull the mean low (tests/bake/probe_filter_test.cpp's furnace shows it).
double tap_weight(const FilterInput& in, const ProbeFilterSettings& s, int32_t i, int32_t j, double tent) {
  if (!in.lit[j]) return 0.0;
  if (j == i) return 1.0;
  const float* li = &in.lum[size_t(i) * 4];
  const float* lj = &in.lum[size_t(j) * 4];
  const double ai = li[0], aj = lj[0];
  double var = in.rel2[i] * ai * ai + in.rel2[j] * aj * aj;
  double d2 = (ai - aj) * (ai - aj);
  for (int a = 1; a < 4; ++a) d2 += double(li[a] - lj[a]) * double(li[a] - lj[a]) / 3.0;
  var *= 7.0 / 3.0;
  double bilateral = 0.0;
  if (var > 0.0)
    bilateral = std::exp(-d2 / (double(s.noise_k) * var));
  else if (d2 == 0.0)
    bilateral = 1.0;
  if (bilateral < 1e-6) return 0.0;
  const float3 pi = kernels::load3(&in.pos[size_t(i) * 3]), pj = kernels::load3(&in.pos[size_t(j) * 3]);
  const float3 delta = pj - pi;
  const float dist = kernels::length(delta);
  if (!(dist > 0.f)) return 0.0;
  const float3 dir = delta * (1.f / dist);
  const double vis = double(chebyshev(in, i, dir, dist)) * double(chebyshev(in, j, dir * -1.f, dist));
  return tent * bilateral * vis;
}

FilterInput make_input(const DdgiResult& r) {
  FilterInput in{r, {}, {}, {}, {}, {}, {}};
  const DdgiVolumeDesc& d = r.desc;
  for (int a = 0; a < 3; ++a) in.irr.counts[a] = in.depth.counts[a] = d.counts[a];
  in.irr.res = kIrradianceTexels;
  in.depth.res = kDepthTexels;
  in.irr.planes_per_row = in.depth.planes_per_row = r.atlas_planes_per_row;
  const int32_t n = d.probe_count();
  const size_t coefs = size_t(d.sh_coefficients()) * 3;
  in.pos.resize(size_t(n) * 3);
  in.lum.resize(size_t(n) * 4);
  in.rel2.resize(size_t(n));
  in.lit.resize(size_t(n));
  // The noise test's floor: below it a probe's estimate counts as exact.
  constexpr double kMinRelative = 1e-4;
  for (int32_t p = 0; p < n; ++p) {
    const auto rest = probe_rest_position(d, p);
    for (int a = 0; a < 3; ++a) in.pos[size_t(p) * 3 + a] = rest[a] + r.offsets[size_t(p) * 3 + a];
    const float* sh = &r.sh[size_t(p) * coefs];
    in.lum[size_t(p) * 4] = kernels::kPi * 0.282095f * luminance(sh);
    const float band1 = 2.f * kernels::kPi / 3.f * 0.488603f;
    in.lum[size_t(p) * 4 + 1] = band1 * luminance(sh + 9);
    in.lum[size_t(p) * 4 + 2] = band1 * luminance(sh + 3);
    in.lum[size_t(p) * 4 + 3] = band1 * luminance(sh + 6);
    const double e = r.stats[p].relative_error;
    in.rel2[p] = std::max(e, kMinRelative) * std::max(e, kMinRelative);
    in.lit[p] = r.states[p] != ProbeState::Inactive && std::isfinite(e) && std::isfinite(in.lum[size_t(p) * 4]);
  }
  return in;
}

struct ProbeOut {
  double neighbour_share = 0.0;  // of the total weight
  double error_after = 0.0;      // sqrt(sum w_j^2 r_j^2) / sum w_j: neighbours' noise taken as independent
};

// Probe i's weights and its new SH and irradiance texels (into sh_out / irr_out at its place).
ProbeOut filter_one(const FilterInput& in, const ProbeFilterSettings& s, int32_t i, std::vector<float>& sh_out,
                    std::vector<float>& irr_out) {
  const DdgiResult& r = in.r;
  const DdgiVolumeDesc& d = r.desc;
  const int c[3] = {i % d.counts[0], (i / d.counts[0]) % d.counts[1], i / (d.counts[0] * d.counts[1])};
  int32_t probe[kTaps];
  double weight[kTaps];
  int taps = 0;
  double total = 0.0, own = 0.0, err2 = 0.0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x >= d.counts[0] || y >= d.counts[1] || z >= d.counts[2]) continue;
        const int32_t j = x + d.counts[0] * (y + d.counts[1] * z);
        const double tent = std::ldexp(1.0, -(std::abs(dx) + std::abs(dy) + std::abs(dz)));
        const double w = tap_weight(in, s, i, j, tent);
        if (w <= 0.0) continue;
        probe[taps] = j;
        weight[taps++] = w;
        total += w;
        err2 += w * w * in.rel2[j];
        if (j == i) own = w;
      }
  ProbeOut out;
  out.neighbour_share = 1.0 - own / total;
  out.error_after = std::sqrt(err2) / total;
  const size_t coefs = size_t(d.sh_coefficients()) * 3;
  for (size_t k = 0; k < coefs; ++k) {
    double sum = 0.0;
    for (int t = 0; t < taps; ++t) sum += weight[t] * r.sh[size_t(probe[t]) * coefs + k];
    sh_out[size_t(i) * coefs + k] = float(sum / total);
  }
  if (r.irradiance_atlas.empty()) return out;
  int oi[2], oj[2];
  in.irr.tile_origin(i, oi[0], oi[1]);
  const int width = r.irradiance_width;
  for (int ty = 1; ty <= in.irr.res; ++ty)
    for (int tx = 1; tx <= in.irr.res; ++tx)
      for (int ch = 0; ch < 3; ++ch) {
        double sum = 0.0;
        for (int t = 0; t < taps; ++t) {
          in.irr.tile_origin(probe[t], oj[0], oj[1]);
          sum += weight[t] * r.irradiance_atlas[(size_t(oj[1] + ty) * width + size_t(oj[0] + tx)) * 4 + ch];
        }
        irr_out[(size_t(oi[1] + ty) * width + size_t(oi[0] + tx)) * 4 + ch] = float(sum / total);
      }
  kernels::oct_fill_border(irr_out.data(), width, 4, oi[0], oi[1], in.irr.res);
  return out;
}

}  // namespace

void filter_probes(DdgiResult& result, const ProbeFilterSettings& settings, ProbeFilterReport& report) {
  report = ProbeFilterReport{};
  if (!settings.enabled) return;
  report.ran = true;
  const int32_t n = result.desc.probe_count();
  if (n == 0 || result.stats.size() != size_t(n) || result.states.size() != size_t(n)) return;
  const FilterInput in = make_input(result);
  std::vector<float> sh_out = result.sh;
  std::vector<float> irr_out = result.irradiance_atlas;
  std::vector<ProbeOut> outs(static_cast<size_t>(n));
  // Each probe reads the unfiltered input and writes its own place: any split gives the same bytes.
  tbb::parallel_for(tbb::blocked_range<int32_t>(0, n, 64), [&](const tbb::blocked_range<int32_t>& range) {
    for (int32_t i = range.begin(); i != range.end(); ++i)
      if (in.lit[i]) outs[i] = filter_one(in, settings, i, sh_out, irr_out);
  });
  for (int32_t i = 0; i < n; ++i) {
    if (!in.lit[i]) continue;
    ++report.lit;
    if (outs[i].neighbour_share > 0.0) ++report.smoothed;
    report.mean_neighbour_weight += outs[i].neighbour_share;
    report.mean_error_before += std::sqrt(in.rel2[i]);
    report.mean_error_after += outs[i].error_after;
  }
  if (report.lit > 0) {
    report.mean_neighbour_weight /= report.lit;
    report.mean_error_before /= report.lit;
    report.mean_error_after /= report.lit;
  }
  result.sh.swap(sh_out);
  result.irradiance_atlas.swap(irr_out);
}

std::string probe_filter_summary(const ProbeFilterReport& r) {
  char text[256];
  std::snprintf(text, sizeof text,
                "probe filter: %d of %d lit probes smoothed, mean neighbour weight %.2f, mean relative error "
                "%.3g before, about %.3g after (estimated, neighbours' noise independent)",
                r.smoothed, r.lit, r.mean_neighbour_weight, r.mean_error_before, r.mean_error_after);
  return text;
}

}  // namespace gibake
