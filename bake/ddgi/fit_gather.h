// What the surface fit takes as the truth at each point (surface_fit.h's E_s and its noise), from
// the light its paths found. A whole gather has one estimate a point: converged paths (f). A both
// gather has two from the same paths: f, and g, the same paths ended at their first hit in the
// probes' own light (path_gather.h ProbeField). g carries one bounce's noise instead of a whole
// path's, but the probes' errors (leaks, interpolation, glow beside lamps) instead of the truth.
// Where light arrives through long paths (closed rooms of bright walls) f is too noisy to trust
// at a fit's path count and g is far closer; where the probes are wrong, g is.
//
// The rule, per region (a cube of a few probe spacings of one volume): R = sum f / sum g over its
// points, so R g keeps g's low noise and takes the whole paths' level, pooled over many points.
// Per probe (its points together, as the noise is pooled): the expected squared relative error of
// R g is its own noise, R's, and the bias R leaves (the squared differences f - R g beyond their
// noise); f's is its noise. Each point takes the blend of R g and the probe's own estimate weighted
// inversely to R g's error and f's, and the blend's noise. The probe's own estimate is f; with
// `own_ratio` it blends f with rho g (rho = sum f / sum g over the probe's points), weighted
// inversely to f's error and rho g's (its noise, rho's, and the bias rho leaves where the probe's
// ended light is wrong by other than one factor). Where the light arrives through rare paths (a
// curtain lit by sunlit stone) a point's f is nearly all noise and rho g far closer. Every estimate
// of noise is from the two halves of the paths.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

namespace gibake {

// Luminance (lux) a point's paths found: the whole paths' (f) and the ended paths' (g, zero unless
// a both gather), each with the estimates of the two halves of its paths.
struct FitPointLight {
  double f = 0.0, f_half[2] = {0.0, 0.0};
  double g = 0.0, g_half[2] = {0.0, 0.0};
  uint32_t probe = 0;               // the probe whose ray found it (points come in probe order)
  std::array<int64_t, 4> region{};  // its probe's region: volume, cell x, y, z
};

struct FitTruth {
  double truth = 0.0;  // luminance (lux)
  double noise = 0.0;  // relative variance, pooled over the probe's points
};

// The truth at each point. `both` false: f, with the noise of f. `own_ratio`: the probe's own
// estimate may be rho g (where g was read in probes already fitted to the whole paths:
// SurfaceFitSettings::passes); false: it is f, as rho g would keep the baked probes' errors between
// its points. Sums in point order: the result does not depend on the thread count.
std::vector<FitTruth> fit_truths(const std::vector<FitPointLight>& points, bool both, bool own_ratio = false);

// The region of a probe at `position` in volume `volume` whose largest spacing is `spacing`.
std::array<int64_t, 4> fit_region(uint32_t volume, const float position[3], float spacing);

}  // namespace gibake
