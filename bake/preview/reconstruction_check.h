// How far the irradiance an engine reconstructs from a bake is from the path-traced truth, at
// surface points a viewer sees. Probes are measured where nobody looks at them; this
// measures the picture: at each sample point the reference irradiance is path-traced with the
// bake's path tracer run to convergence (cosine-weighted paths from the point: every bounce until
// Russian roulette ends it, whatever the bake's --bounces; emitters and sky, no
// punctual light at the point itself, exactly what the probes hold), the baked one is read with the
// runtime loader's sampler (loader::BakeFile::sample_ddgi over every DDGI volume, blended as
// docs/FORMAT.md "Several volumes" says; one volume's sample_irradiance when asked; the defaults an engine uses), and
// both are shaded as `preview --mode lit` shades a pixel:
//   albedo x (direct punctual light with a shadow ray + E) / pi + emission.
// Points come in patches of 4x4, the analogue of an 8x8-pixel block of a preview: a patch's ratio
// baked / reference is that of its summed luminance, which is what a block comparison of a lit
// preview against `preview --reference` measures, without rendering an image (and the reference
// noise of a patch is that of 16 x rays paths).
//
// Patches: with cameras, 8x8-pixel blocks of their views picked evenly, 4x4 points in each (what
// `preview` renders); otherwise what the active probes (of every volume read) see: from a probe picked at random,
// a direction at random, and a 4x4 grid of rays 2.5 degrees across around it, each to its first
// front-facing hit (surfaces inside walls or under floors, which no camera sees, are never picked).
// Deterministic: every patch, point and path is keyed by (seed, patch, point, ray).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/preview/ended_path_hits.h"
#include "bake/preview/preview.h"
#include "bake/scene/prepare.h"
#include "bake/scene/sky.h"
#include "bake/scene/texture_lod.h"
#include "bake/trace/path_gather.h"
#include "gibake/loader.hpp"
#include "io/context.h"
#include "io/results/ddgi_result.h"
#include "io/status.h"
#include "kernels/shade.h"

namespace gibake {

// The reference's paths made, traced and summed per point by a device instead of the CPU (the
// Vulkan bake's path tracer, bake/vulkan/reference_paths.h): for each point, its `rays` paths as
// reconstruction_check.cpp makes them (stratified cosine-weighted directions keyed by the point's
// key and `salt`, none below the geometric surface), each traced as trace_radiance traces it, and
// their radiance summed in path order, with the reference's path length and footprint.
struct ReferencePoint {
  kernels::float3 origin, n, ng;  // the paths' origin (off the surface), shading and geometric normal
  uint64_t key = 0;
};
struct ReferencePathParams {
  uint32_t rays = 0;  // paths per point
  uint64_t salt = 0;
  int bounces = 4, roulette_depth = 3;
  float cone_spread = 0.f, shadow_bias = 1e-4f;
};
struct ReferencePointSums {
  kernels::float3 sum;            // radiance of the traced paths
  double half_lum[2] = {0.0, 0.0};  // luminance of each half of the strata's checkerboard
  uint32_t half_count[2] = {0, 0};  // paths in each half
  uint64_t traced = 0, shadow_rays = 0, bounce_rays = 0;
  // With end_paths_in: the same paths had each ended at its first hit in the probe field
  // (trace_surface_radiance's probe_lit), and their halves' luminance.
  kernels::float3 ended_sum;
  double ended_half_lum[2] = {0.0, 0.0};
};
class ReferencePathDevice {
 public:
  virtual ~ReferencePathDevice() = default;
  // Whether the device's scene is lit by exactly these lights and this sky (else the CPU traces).
  virtual bool lights_match(const std::vector<kernels::ShadeLight>& lights, const Sky& sky) const = 0;
  virtual uint64_t max_paths() const = 0;  // paths one trace() takes at most (points x rays)
  virtual Status trace(const std::vector<ReferencePoint>& points, const ReferencePathParams& params,
                       std::vector<ReferencePointSums>& out) = 0;
  virtual std::string name() const = 0;  // for the bake's notes
  // From now on trace() also ends each path at its first hit in `file`'s probes, read as
  // BakeFile::sample_ddgi reads them with default options (ReferencePointSums::ended_*); null: no
  // longer. A failure (the device cannot hold or bind the probes) leaves it off: the CPU ends them.
  virtual Status end_paths_in(const loader::BakeFile* file) {
    return file ? Status::error(ExitCode::RuntimeFailure, "", "reference paths", "this device reads no probes")
                : Status::ok();
  }
};

struct ReconstructionSettings {
  uint32_t patches = 128;  // 4x4-point patches (blocks)
  uint32_t rays = 128;     // reference paths per point (cosine-weighted, stratified): 2048 a patch
  // A second pass for the patches whose reference is noisier than this relative standard error:
  // their points traced again with the paths that reach it (the first pass only chose how many),
  // within `ray_budget` paths a point on average over both passes (0: 32 x rays where a device
  // traces them, 4 x on the CPU), at most 64 x rays at a point. A noisy reference reads a right
  // bake as wrong: at 9% a bake equal to the truth scores about 73% of patches within 10%.
  // 0: one pass.
  float target_noise = 0.03f;
  uint32_t ray_budget = 0;
  uint64_t seed = 0;
  // Reference path length: converged whatever the bake's --bounces (path_gather.h); analytic
  // tests may shorten it to match a closed form.
  int bounces = kReferenceBounces;
  int roulette_depth = 3;
  float within = 0.10f;   // "within" means |ratio - 1| <= this
  // Patches below this fraction of the mean reference luminance are left out of the ratios (black
  // shadow against black shadow says nothing), as the block comparison leaves out dark blocks.
  float floor_fraction = 0.001f;
  loader::SampleOptions sample;  // how the baked irradiance is read (loader defaults)
  // Patches from cameras' views instead of from the probes: their 8x8-pixel blocks of width x
  // height, patch k from camera k mod N (so N cameras share the patches evenly).
  std::vector<PreviewCamera> cameras;
  int width = 320, height = 180;
  // Where the reference paths are traced: null, or a device whose lighting differs, the CPU.
  ReferencePathDevice* device = nullptr;
};

// One patch: the position and normal of its first point, sums over its points.
struct ReconstructionPatch {
  std::array<float, 3> position{}, normal{};
  uint32_t points = 0;                 // of the 16 that met a visible surface
  float reference = 0.f, baked = 0.f;  // summed luminance of the shaded radiance, cd/m^2
  float indirect_reference = 0.f, indirect_baked = 0.f;  // summed luminance of E alone, lux
  float reference_stderr = 0.f;        // standard error of `reference` from its paths
};

// A distribution of ratios baked / reference: the share within `within` of 1, quantiles, and
// |ratio - 1| at the 90th percentile (one number for "how wrong the worst tenth is").
struct RatioDistribution {
  double within = 0.0, p10 = 0.0, median = 0.0, p90 = 0.0, p90_error = 0.0;
};
// The distribution of `ratios`, "within" counting those within `within` of 1.
RatioDistribution ratio_stats(std::vector<double> ratios, double within);

struct ReconstructionError {
  uint32_t patches = 0;  // patches with a point on a visible surface
  uint32_t counted = 0;  // ... above the floor: the ratios below are over these
  RatioDistribution shaded;    // shaded radiance (luminance), as a pixel of the lit preview
  RatioDistribution indirect;  // indirect irradiance alone (E, what the probes carry)
  // The reference's own noise: median relative standard error of a patch's shaded radiance.
  double reference_noise = 0.0;
  uint32_t retraced = 0, retraced_rays = 0;  // ReconstructionReference's
  uint64_t rays = 0;  // camera/probe rays, reference paths' rays and shadow rays
  double seconds = 0.0;
  std::string source;                        // "probes' view", "camera" or "N cameras"
  std::vector<ReconstructionPatch> samples;  // every patch with points, in patch order
};

// A measurement in two halves, so that a bake can trace the reference beside the write of its file:
// the patches' points with their path-traced reference and direct light (nothing baked is read),
// then the baked irradiance at every point and the ratios. Together they are measure_reconstruction,
// bit for bit.
struct ReconstructionReference {
  struct Point {
    kernels::float3 p, n, albedo, direct;  // what the baked half reads, in the order it sums them
  };
  std::vector<kernels::float3> probes;       // the active probes the patches were picked from
  std::vector<ReconstructionPatch> patches;  // reference sums (baked sums still zero)
  std::vector<std::vector<Point>> points;    // per patch, its points that met a visible surface
  std::vector<uint64_t> rays;                // per patch
  std::string device;                        // the device that traced the paths (empty: the CPU)
  uint32_t retraced = 0, retraced_rays = 0;  // patches of the second pass, and its most paths a point
  double seconds = 0.0;
};
Status trace_reconstruction_reference(const PreparedScene& prepared, const TextureLod& lod,
                                      const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                                      const std::vector<kernels::float3>& probes,
                                      const ReconstructionSettings& settings, const Context& ctx,
                                      ReconstructionReference& out);
// In the caller's arena.
void finish_reconstruction(const ReconstructionReference& reference, const DdgiReader& ddgi,
                           const ReconstructionSettings& settings, ReconstructionError& out);
// The active probes' positions of every volume read (the probe-view patches start there).
std::vector<kernels::float3> active_probes(const DdgiReader& ddgi);
// The same from the results a file will hold, in the loader's arithmetic (volumes in file order).
std::vector<kernels::float3> active_probe_positions(const std::vector<const DdgiResult*>& volumes);
bool same_positions(const std::vector<kernels::float3>& a, const std::vector<kernels::float3>& b);

// A surface point the atlas fit (bake/ddgi/surface_fit.h) reads: the first visible surface along
// a ray (a front face, or either face of a double-sided material), its normals facing the ray.
struct VisibleSurface {
  bool valid = false;
  kernels::float3 p, n, ng;
};
// The first visible surface from `origin` along unit `dir` no farther than `reach`.
VisibleSurface visible_surface(const PreparedScene& prepared, const TextureLod& lod, const kernels::float3& origin,
                               const kernels::float3& dir, float reach);

// Path-traced irradiance (lux) at surface points: the reference's cosine-weighted paths (converged,
// full-resolution textures; Russian roulette after `roulette_depth` hits, the reference's unless
// given), `rays` a point keyed by (seed, point index), lit as `settings_json`
// records (as the check reads it); on `device` when its lighting matches, else (or when the device
// fails) on the CPU. Invalid points get zero.
// `probe_field` set: each path ends at its first hit, lit from there by it (PathSetup::probe_field),
// on the CPU; with `whole_paths_too` each path also goes on to its end: `irradiance` is then the
// whole paths' and `probe_lit` the same paths ended at their first hit. A device traces the whole
// paths, and ends them too where it reads the field's probes itself (ProbeField::file,
// ReferencePathDevice::end_paths_in); else the CPU traces the ended ones.
struct SurfaceLight {
  kernels::float3 irradiance;
  float half[2] = {0.f, 0.f};  // luminance of the irradiance each half of the paths estimates
  kernels::float3 probe_lit;   // zero unless both were asked for
  float probe_half[2] = {0.f, 0.f};
};

// `keep` (with probe_field and whole_paths_too): the paths' first hits are kept, unread
// (ended_path_hits.h), for the caller to end in another field (end_kept_paths); `probe_lit` stays
// zero. Kept where the CPU traces the paths (keep->complete); a device traces the whole paths alone
// and keeps none.
Status trace_surface_irradiance(const PreparedScene& prepared, const TextureLod& lod, const std::string& settings_json,
                                const std::vector<VisibleSurface>& points, uint32_t rays, uint64_t seed,
                                ReferencePathDevice* device, const Context& ctx, std::vector<SurfaceLight>& out,
                                const ProbeField* probe_field = nullptr, bool whole_paths_too = false,
                                int roulette_depth = ReconstructionSettings{}.roulette_depth,
                                EndedPathHits* keep = nullptr);

// Measures a bake's DDGI volumes (a file: all of them blended; a volume: that one alone) against
// the scene it was baked from. `lights`, `sky`: the bake's lighting.
Status measure_reconstruction(const PreparedScene& prepared, const TextureLod& lod,
                              const std::vector<kernels::ShadeLight>& lights, const Sky& sky,
                              const DdgiReader& ddgi, const ReconstructionSettings& settings,
                              const Context& ctx, ReconstructionError& out);

// The same for a bake file: lighting and sky from its recorded settings (as `preview` reads
// them; never its path length); every DDGI volume blended, or with `only_volume` that volume alone
// (`preview --volume N`). A null `only_volume` reads them all.
Status measure_bake_reconstruction(const PreparedScene& prepared, const TextureLod& lod, const loader::BakeFile& bake,
                                   const uint32_t* only_volume, ReconstructionSettings settings, const Context& ctx,
                                   ReconstructionError& out);

// measure_bake_reconstruction (every volume blended) in two halves for a bake whose file is not
// written yet: the reference from `settings_json` (what the file's metadata "settings" will hold:
// its lighting) and the active probes (active_probe_positions); then the baked half from
// the file. The file's active probes are compared with the reference's first: if they ever differed
// the whole measurement would be made from the file.
Status trace_bake_reconstruction_reference(const PreparedScene& prepared, const TextureLod& lod,
                                           const std::string& settings_json, const std::vector<kernels::float3>& probes,
                                           ReconstructionSettings settings, const Context& ctx,
                                           ReconstructionReference& out);
Status finish_bake_reconstruction(const PreparedScene& prepared, const TextureLod& lod, const loader::BakeFile& bake,
                                  const ReconstructionReference& reference, ReconstructionSettings settings,
                                  const Context& ctx, ReconstructionError& out);

// One line for people: the source, the patches counted, within 10%, p10/median/p90, the indirect
// light's figures, the reference noise and the seconds.
std::string reconstruction_summary(const ReconstructionError& error);

}  // namespace gibake
