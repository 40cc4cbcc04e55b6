// DDGI probe bake on the CPU (Embree + TBB). Orchestrates grid placement, relocation,
// tracing, classification, multi-bounce integration; the math lives in kernels/.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bake/ddgi/probe_filter.h"
#include "bake/ddgi/probe_grid.h"
#include "bake/ddgi/surface_fit.h"
#include "bake/run/backend.h"
#include "bake/run/run_context.h"
#include "bake/scene/lights.h"
#include "bake/trace/path_gather.h"
#include "io/context.h"
#include "io/results/ddgi_result.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct BakeSetup;
struct SetupSettings;

enum class LightSampling : uint8_t { All = 0, Random = 1 };

// How light arriving at a probe ray's hit is gathered. Path: the ray continues as a path (bake/trace/path_gather.h),
// converging to the path-traced truth. Probes: the runtime approximation DDGI engines use, where bounce k
// reads the light at each hit from pass k-1's probes (fast; biased, see docs/ARCHITECTURE.md).
enum class Gather : uint8_t { Path = 0, Probes = 1 };


// --bounces by gather. The path gather's paths run until Russian roulette ends them, as the
// reference's do (a probe holds converged light, DESIGN.md): a bound that truncated them would
// lose the many orders of light a room of bright walls keeps, and roulette already pays for long
// paths only where surfaces are bright. The probe-feedback gather's bounces are passes over every
// probe, each a full re-read, so its default and its bound stay small.
constexpr int kPathGatherBounces = kReferenceBounces;
constexpr int kProbeGatherBounces = 4;
constexpr int kMaxProbeGatherBounces = 64;
// A near volume's reach in its probe spacings. A surface point reads the corners of the cell it lies
// in, pushed off the surface by the normal bias: within about two spacings of it, with a margin.
constexpr float kNearSurfaceSpacings = 2.5f;

struct DdgiSettings {
  GridSettings grid;
  uint32_t rays = 256;       // rays per probe per batch (spherical Fibonacci)
  uint32_t max_rays = 0;     // per-probe cap with target_error (0: 8 x rays)
  float target_error = 0.f;  // > 0: stop a probe once its relative standard error is below (the CLI's default: 0.05)
  // With target_error, > 0: rays per probe on average (the CLI's default: 1024), held by each fixed
  // block of a volume's probes (io/results/ddgi_shard.h: kProbeBlock), so that shards decide as the
  // one-go bake; a block's adaptive batches go to its probes with the largest error first until
  // its share is spent.
  uint32_t ray_budget = 0;
  uint64_t seed = 0;
  Gather gather = Gather::Path;
  int bounces = kPathGatherBounces;  // path vertices after the first hit / probe-feedback passes
  int roulette_depth = 3;  // path vertices before Russian roulette (path gather)
  float energy_conservation = 1.f;
  int sh_order = 2;  // 1 or 2
  LightSampling light_sampling = LightSampling::All;
  std::array<float, 3> sky{0.f, 0.f, 0.f};  // constant sky radiance, cd/m^2
  std::string sky_hdr;                      // equirect EXR (overrides `sky`)
  float sky_hdr_scale = 1.f;
  std::vector<SunLight> suns;
  bool relocate = true;
  float relocate_fraction = 0.3f;  // of the min cell size
  float relocate_max_fraction = 0.45f;
  uint32_t relocate_rays = 64;
  int relocate_iterations = 2;
  // > 0: only the probes with a surface within this many metres of their rest position are
  // relocated and traced (bake/ddgi/near_surface.h); the others are left out,
  // Inactive in the file with no rays, so the sampler answers there from the other volumes. A fine
  // volume over open space then costs what its probes near surfaces cost (--probe-volume ...:near,
  // --near-camera).
  float near_surface_reach = 0.f;
  float backface_threshold = 0.25f;
  bool cgal_check = true;       // confirm inside probes against closed meshes (CGAL)
  float blend_cutoff = kDefaultBlendCutoff;    // alphaMode BLEND traced as MASK with this cutoff; 0: opaque
  int max_atlas_width = 16384;  // texels; atlases wrap Y-planes onto more rows to stay within
  // false: the file holds no irradiance atlas, and the samplers read a probe's irradiance from its
  // SH, which ring around bright sources below a surface's horizon (loader.hpp SampleOptions).
  bool irradiance_atlas = true;
  // Interior texels a side of the file's depth tiles: kDepthTexels (as baked), 8 or 4. Fewer
  // coarsen the finished atlas (bake/ddgi/depth_tiles.h) to about a third or a ninth of its bytes,
  // for a coarser visibility test; the bake itself always integrates kDepthTexels.
  int depth_tile = kDepthTexels;
  float normal_bias = 0.02f;    // m, for sampling the previous bounce
  float smooth_backface = 0.3f;
  float max_distance = 0.f;                        // depth for misses; 0: 1.5 x diagonal of scene+grid bounds
  uint64_t max_memory_bytes = uint64_t(16) << 30;  // cap on the estimated host working set (--max-memory)
  // Where the bake runs (bake/run/backend.h). On Vulkan relocation, the trace with its ray generation,
  // integration and statistics, and the probe-feedback bounce passes run on the device; import,
  // voxels, classification and the file stay on the CPU (docs/ARCHITECTURE.md, "Vulkan backend").
  // The settings JSON names the backend and device only when Vulkan ran, so CPU bakes keep their bytes.
  BackendSettings backend;
  // Probes in enclosed space (a voxel flood fill from outside cannot reach them) whose rays all
  // met geometry and brought back no light are made inactive. Without a voxel grid in the run
  // context the bake voxelizes the scene itself at enclosure_resolution voxels on its longest side
  // (0: no enclosure test).
  int32_t enclosure_resolution = 128;
  // After the bake (or the shard merge): each probe averaged with its visible neighbours where
  // their difference is within the noise (bake/ddgi/probe_filter.h). Recorded in the settings JSON.
  ProbeFilterSettings filter;
  // Irradiance atlases fitted to path-traced surface points once every volume is baked
  // (bake/ddgi/surface_fit.h, bake/pipeline/surface_fit_stage.h). Recorded in the settings JSON.
  SurfaceFitSettings fit;
};

struct DdgiReport {
  int32_t probes = 0, active = 0, inactive = 0, relocated = 0;
  int32_t enclosed = 0;  // inactive because they sit in enclosed space that no light reaches
  int32_t sky_only = 0;  // no ray hit geometry (state SkyOnly)
  int32_t left_out = 0;  // no surface within DdgiSettings::near_surface_reach: no rays, Inactive
  uint64_t primary_rays = 0, shadow_rays = 0, relocation_rays = 0, bounce_rays = 0;
  uint64_t bounce_hits = 0;  // probe-ray hits that reflect light (re-shaded by every bounce pass)
  uint64_t total_rays() const { return primary_rays + shadow_rays + relocation_rays + bounce_rays; }
  std::vector<std::pair<std::string, double>> stage_seconds;  // in order
  double seconds_total = 0.0;
  uint64_t memory_estimate = 0;  // bytes: the host working set estimated for the route that ran
  bool cgal_checked = false;
  uint32_t cgal_inside = 0;            // probes CGAL puts strictly inside a closed solid
  uint32_t cgal_disagreements = 0;     // ... of which the ray test left active
  uint32_t cgal_inactive_outside = 0;  // ray-inactive probes outside every closed solid (open meshes)
  size_t masked_triangles = 0;
  bool black = false;
  GridPlacement placement;  // what the default grid's fit to the voxels did (probe_grid.h)
  ProbeFilterReport filter;
};

// Settings as a JSON object (DdgiResult::settings_json); `ran_on` (optional): the backend the bake
// ran on, recorded when it is Vulkan.
std::string ddgi_settings_json(const DdgiSettings& settings, const BackendChoice* ran_on = nullptr);

// Validates settings (BadArguments on nonsense values).
Status validate_ddgi_settings(const DdgiSettings& settings);

// The most rays a probe is traced with: with target_error, max_rays (0: 8 x rays) but never below
// one batch; else exactly one batch.
uint32_t probe_ray_cap(const DdgiSettings& settings);
// `settings` with probes averaging `ray_budget` rays (0: unchanged): with --target-error, that
// budget (at most settings.ray_budget when it has one) and a first batch of half of it (at most
// settings.rays), so adaptive rays still place the other half; with fixed rays, that many (at most
// settings.rays). What refined volumes are baked with (volume_plan.h: planned_volume_settings).
DdgiSettings with_ray_budget(const DdgiSettings& settings, uint32_t ray_budget);

// How an adaptive bake's probes ended against its target error, from the result's statistics: the
// probes with light (not inactive) and those of them whose estimated relative error stayed at or
// above the target (the ray budget or the per-probe cap ran out first), with the median of their errors.
// Where these probes are what a view reads, the picture is noise-limited (Sponza's arcade:
// docs/BENCHMARKS.md); a shard's or merged result reads the same.
struct AdaptiveOutcome {
  uint32_t lit = 0;
  uint32_t above_target = 0;
  float median_error_above = 0.f;
};
AdaptiveOutcome adaptive_outcome(const DdgiResult& result, float target_error);

// What the set-up stage reads of the settings (bake/run/bake_setup.h).
SetupSettings setup_settings(const DdgiSettings& settings);
// What `--backend auto` weighs (bake/run/backend_cost.h): the bake's `probes` (all of them, also in a
// shard) traced on `threads` CPU threads.
WorkloadEstimate ddgi_workload(const DdgiSettings& settings, uint64_t probes, uint64_t triangles, int threads);

// Bakes the probes; `run` hands in what the caller already built (bake/run/run_context.h) and the
// platform the set-up and device come from (run.platform, required; bake/pipeline/devices.h has
// the overload without a run context).
Status bake_ddgi(const Scene& scene, const DdgiSettings& settings, const RunContext& run, const Context& ctx,
                 DdgiResult& result, DdgiReport& report);

// One volume of bake_ddgi_together: bake_ddgi's arguments, which outlive the call.
struct DdgiVolumeJob {
  const DdgiSettings* settings = nullptr;
  RunContext run;
  Context ctx;
  DdgiResult* result = nullptr;
  DdgiReport* report = nullptr;
};

// bake_ddgi for each job in order, with the same results, except that on a device the probes of
// consecutive volumes whose settings differ only in the grid are traced in one stage
// (TraceStage::parts) while their working set together stays within --max-memory: an adaptive pass
// there costs nearly as much for a few probes as for thousands, and many small volumes (refinement)
// would otherwise pay it volume after volume. The stage's seconds go to the first volume of each
// group. A shard's volume, or one capturing rays, is baked alone.
Status bake_ddgi_together(const Scene& scene, const std::vector<DdgiVolumeJob>& jobs);

}  // namespace gibake
