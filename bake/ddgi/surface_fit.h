// Irradiance atlases fitted to the surfaces they light (--surface-fit). A probe's texels hold the
// light at the probe; a surface between probes reads a weighted blend of them, and where the light
// changes over less than a probe spacing (a sunlit strip, a corner) that blend misses the light the
// surface receives. The fit keeps the sampler as it is and changes what it reads: each irradiance
// atlas texel gets a gain g (its RGB scaled alike) so that, at surface points near the probes, the
// runtime sampler's answer (loader::BakeFile::sample_ddgi, the engine's defaults) matches the
// path-traced irradiance there. Least squares over the points, each residual relative to the baked
// value (so dim and bright surfaces count alike and a point the probes already get right holds its
// texels), and priors that keep texels few points read near their probe's light:
//   minimise  sum_s w_s ((sum_t a_st (G_p(t) + d_t) - E_s) / B_s)^2 + lambda' sum_t d_t^2
//             + lambda_probe sum_p (G_p - 1)^2,
// with a_st the sampler's weight of texel t at point s times the texel's luminance, B_s = sum_t a_st
// (the baked luminance), E_s the path-traced luminance and w_s the point's trust in it
// (SurfaceFitSettings::trusted_noise), lambda' = texel_prior(). Solved once so, then again with each
// B_s replaced by B_s q_s^relative_to_fit, q_s the first solve's fitted over baked luminance at s
// (SurfaceFitSettings::relative_to_fit says why). A border texel is its interior source
// (kernels::oct_fill_border), refilled after the fit. The normal equations are solved to convergence
// (fit_solve.h: every gain within a thousandth of the solution, the lightly read texels too; the
// probes' gains eliminated) with sums in a fixed order: the gains do not depend on the thread count.
// A texel's gain is its probe's gain G (one for the whole tile, pulled towards 1 by lambda_probe)
// plus its own deviation d (pulled towards 0 by lambda): light that a probe's texels all miss alike
// is corrected by all its points together.
// The SH is left alone: it stays the probe's own incident light (DESIGN.md), which engines that
// read the SH, and the bake's checks at the probes, rely on.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/context.h"
#include "io/results/ddgi_result.h"
#include "io/status.h"
#include "kernels/vec.h"

namespace gibake {
namespace loader {
class BakeFile;
}

// What lights the fit's points (--fit-gather).
// Both (the default level's): each path traced whole and also ended at its first hit as Probes
//   says; each point's truth blends the two (fit_gather.h). With a second pass
//   (SurfaceFitSettings::passes) the paths are ended in the probes as the whole paths alone fit
//   them, not in the baked probes. The whole paths run on the bake's device when it has one, the
//   ended ones on the CPU or on a device that reads the probes.
// Paths (final's): converged paths to the end (Russian roulette), on the bake's device when it
//   has one.
// Probes: a path bounces once and reads the probes' own (unfitted) light where it lands, plus the
//   punctual lights there (a first hit on an emitter goes on as a full path: path_gather.h). The
//   probes have converged what longer paths carry, so a point's noise is one bounce's: where light
//   arrives through long paths (closed rooms of bright walls) the points are no longer too noisy
//   to trust. Beyond the first bounce the light is then the probes' interpolation, not the truth:
//   their leaks and their errors near lamps enter the fit instead of being corrected by it
//   (docs/BENCHMARKS.md "The fit's gather"). The CPU traces them (the device's path kernel reads
//   no probes).
enum class FitGather : uint8_t { Probes = 0, Paths, Both };
const char* fit_gather_name(FitGather gather);  // "probes", "paths", "both"
bool parse_fit_gather(const std::string& text, FitGather& out);

struct SurfaceFitSettings {
  bool enabled = false;
  FitGather gather = FitGather::Both;  // --fit-gather
  uint32_t directions = 64;       // rays from each lit probe to the surfaces around it (--fit-directions)
  uint32_t paths = 144;           // paths a point (--fit-paths), each as `gather` says
  // Hits of a whole path before Russian roulette may end it (PathSetup::roulette_depth). From the
  // first hit, a path costs less, and the paths a point that the time saved buys lower its noise by
  // more than the roulette raises it; the points' paths are the fit's noise on a CPU
  // (docs/BENCHMARKS.md "The default's arcade: one bake's noise"). Final keeps the reference's 3.
  int roulette_depth = 1;
  // The side of the cubes over which the paths ended at their first hit share one read of the
  // probes (CachedProbeField), as a share of the finest probe spacing; 0 reads them at every hit.
  // The probes' light changes over their spacing, so a read a few centimetres off serves as well,
  // and most hits land on patches other hits have read.
  float read_cell = 0.25f;
  // With Both, 2: the atlases are fitted to the whole paths alone, the same paths are ended at
  // their first hit in those fitted probes, and the baked atlases are fitted to the blend. Ended in
  // the baked probes instead, the paths read their errors (a curtain lit through rare paths reads
  // too bright there), and the fit follows them where the whole paths are too noisy to say otherwise
  // (docs/BENCHMARKS.md "The default's arcade: one bake's noise"). The CPU keeps each path's first
  // hit rather than reading the baked probes, so the pass costs the reads it moves and a solve.
  // 1: the paths ended in the baked probes, one fit.
  uint32_t passes = 2;            // --fit-passes
  uint64_t max_samples = 262144;  // points over every volume (--fit-samples); an even subset when more are found
  float reach = 1.5f;             // a point lies within this many of its probe volume's largest spacing
  // Pull of each texel's gain towards its probe's, for points of kLambdaPaths paths; the fit pulls
  // with lambda x kLambdaPaths / paths (texel_prior()). Read as ridge regression the pull is the
  // points' noise variance over the deviations' own, and a point's noise variance falls as one over
  // its paths (docs/BENCHMARKS.md "The texels' own pull").
  float lambda = 0.3f;
  // Pull of each probe's gain (the part all its texels share) towards 1. Light that all of a probe's
  // points say it misses alike moves it with all of them behind it; weaker pulls followed the
  // points' noise in shade (docs/BENCHMARKS.md "The surface fit").
  float lambda_probe = 10.f;
  // A point counts sigma^2 / (noise + sigma^2) of a noiseless one, noise being the relative variance
  // of its path-traced value: where the paths are too few to tell light from noise (light that
  // arrives through long paths), the gains stay near 1 instead of following the noise.
  float trusted_noise = 0.5f;  // sigma: a point with this relative standard error counts half
  // How far a point's residual is taken relative to the fitted light rather than the baked light it
  // corrects: 0 relative to B_s, 1 to the first solve's fitted value F_s, between to B_s^(1-p) F_s^p.
  // A point's noise is relative to its true light, and where the probes are wrong B_s is a poor
  // stand-in for it: points the probes read too dark then weigh more than their noise says, and
  // their skewed light (a few bright paths) pulls their texels up, so the picture leans bright where
  // the probes read one texel for surfaces lit differently. F_s, pooled over the texel's points,
  // is nearer the truth without the point's own noise, which weighing by E_s itself would bring
  // (docs/BENCHMARKS.md "The fit's residual relative to its own light").
  float relative_to_fit = 0.5f;
  float min_gain = 0.25f, max_gain = 4.f;
};

// The paths a point at which SurfaceFitSettings::lambda is the pull as it is.
constexpr uint32_t kLambdaPaths = 128;
// The pull on each texel's own deviation that the fit uses: lambda x kLambdaPaths / paths.
double texel_prior(const SurfaceFitSettings& s);

struct SurfaceFitSample {
  kernels::float3 p, n;  // surface point and shading normal, as a viewer's pixel reads them
  float truth = 0.f;     // luminance of the path-traced irradiance there, lux
  float noise = 0.f;     // relative variance of `truth` (pooled over the points near it)
};

struct SurfaceFitReport {
  uint64_t samples = 0;  // points given
  uint64_t used = 0;     // ... that the sampler answers at with some light
  uint64_t texels = 0;   // texels fitted (interior texels some point reads)
  int iterations = 0;
  // Over the used points (the fit's own points: a check on other points is the reconstruction
  // check's): share within 10% of the path-traced value and the median ratio, before and after.
  double within_before = 0.0, within_after = 0.0, median_before = 0.0, median_after = 0.0;
  double gain_p10 = 1.0, gain_median = 1.0, gain_p90 = 1.0;
  double seconds = 0.0;
};

// The sampler's side of the fit's rows: for each point, the atlas texels the runtime sampler reads
// there and the weight of each (a_st of the least squares). They depend on where the points are
// and on the atlases before the fit, not on the points' light, so a bake with a device builds them
// while the device traces the points' paths.
struct FitRows {
  struct Entry {
    uint32_t volume = 0;
    uint32_t texel = 0;  // y * width + x of the interior texel that holds it (a border texel's source)
    float a = 0.f;       // the sampler's weight times the texel's luminance
  };
  std::vector<size_t> start;  // point i's entries are [start[i], start[i + 1])
  std::vector<Entry> entries;
};

// The rows of `points` (their p and n; truth and noise unread), in point order. Runs in a task
// arena of ctx's threads; the rows do not depend on the thread count.
FitRows fit_rows(const loader::BakeFile& file, const std::vector<SurfaceFitSample>& points,
                 const std::vector<DdgiResult*>& volumes, const Context& ctx);

// Fits the irradiance atlases of `volumes` (the results `file` was encoded from, in its order) to
// the samples and writes the gains into them (interior texels, then every touched tile's border).
// `rows` are fit_rows of the same samples, file and volumes. InvalidInput when the file and the
// results disagree in layout, or the rows and the samples in number.
Status fit_irradiance_atlases(const loader::BakeFile& file, const std::vector<SurfaceFitSample>& samples,
                              const FitRows& rows, const SurfaceFitSettings& settings,
                              const std::vector<DdgiResult*>& volumes, const Context& ctx, SurfaceFitReport& report);
// The same, building the rows first.
Status fit_irradiance_atlases(const loader::BakeFile& file, const std::vector<SurfaceFitSample>& samples,
                              const SurfaceFitSettings& settings, const std::vector<DdgiResult*>& volumes,
                              const Context& ctx, SurfaceFitReport& report);

// One line for people: points, texels, the fit's points before and after, the gains, seconds.
std::string surface_fit_summary(const SurfaceFitReport& report);

}  // namespace gibake
