// The bake command's arguments as parsed by CLI11, and their conversion into the library's
// settings structs (every check of a value's meaning happens here or in the library).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/quality.h"
#include "bake/ddgi/volumes.h"
#include "bake/lpv/lpv.h"
#include "bake/voxel/voxelize.h"
#include "io/bakefile/bake_file.h"
#include "io/status.h"
#include "cli/options.h"
#include "cli/vxgi_stage.h"

namespace gibake::cli {

struct BakeArgs {
  std::string scene;
  std::string out;
  bool ddgi = false;
  unsigned threads = 0;
  std::string progress = "auto";
  float probe_spacing = 0.f;
  std::string probe_counts, grid_min, grid_max;
  float padding = 0.f;
  std::string gather = "path";
  std::string backend = "auto";  // --backend auto|cpu|vulkan
  std::string vulkan_device;     // --vulkan-device index|name|lavapipe
  std::string cache_dir;         // --cache-dir DIR|off; empty: $GIBAKE_CACHE_DIR, else the user's cache
  // --quality: the level's preset (bake/ddgi/quality.h) sets the members it governs; those given
  // explicitly (named in `given`, in the order of kQualityOptions) are applied over it. The
  // members' own values are the default level's, which --help shows.
  std::string quality = "default";
  std::vector<std::string> given;
  uint32_t rays = quality_preset(Quality::Default).rays;  // see docs/cli/bake.md, --rays
  uint32_t max_rays = quality_preset(Quality::Default).max_rays;
  float target_error = quality_preset(Quality::Default).target_error;  // 0: exactly --rays a probe
  uint32_t ray_budget = quality_preset(Quality::Default).ray_budget;  // mean rays a probe per block; 0: none
  uint64_t seed = 0;
  int bounces = -1;  // -1: the gather's default (kPathGatherBounces, kProbeGatherBounces)
  float energy_conservation = 1.f;
  int sh_order = 2;
  std::string light_sampling = "all";
  std::string sky;
  std::string sky_hdr;
  float sky_hdr_scale = 1.f;
  std::vector<std::string> suns;
  std::string relocate = "on";
  std::string probe_filter = "on";  // --probe-filter on|off (the level's unless given)
  std::string surface_fit = "on";   // --surface-fit on|off (the level's unless given)
  // --fit-directions (the level's unless given)
  uint32_t fit_directions = quality_preset(Quality::Default).fit_directions;
  uint64_t fit_samples = quality_preset(Quality::Default).fit_samples;  // --fit-samples (the level's unless given)
  uint32_t fit_paths = quality_preset(Quality::Default).fit_paths;      // --fit-paths (the level's unless given)
  std::string fit_gather = "both";                                      // --fit-gather (the level's unless given)
  uint32_t fit_passes = quality_preset(Quality::Default).fit_passes;    // --fit-passes 1|2 (the level's unless given)
  // --fit-solves 1|2 (the level's unless given)
  uint32_t fit_solves = quality_preset(Quality::Default).fit_relative_to_fit > 0.f ? 2u : 1u;
  std::string closed_mesh_check = "on";
  float blend_cutoff = kDefaultBlendCutoff;
  int max_atlas_width = 16384;
  uint64_t max_probes = uint64_t(1) << 21;
  uint64_t max_memory = uint64_t(16) << 30;  // --max-memory: every bake kind's estimated host working set
  uint64_t probe_budget = quality_preset(Quality::Default).probe_budget;  // --probe-budget: the spacing rule's cap
  std::vector<std::string> probe_volumes;  // --probe-volume MIN:MAX[:SPACING], repeatable
  std::vector<std::string> near_cameras;   // --near-camera VIEW, repeatable (cli/check_camera.h)
  float near_fov = 0.f;                    // --near-fov (0: the glTF camera's, else 50)
  float near_spacing = 0.f;                // --near-spacing M (0: a quarter of the finest spacing there)
  std::string default_volume = "on";       // --default-volume on|off
  std::string detail_volumes = "auto";     // --detail-volumes auto|off
  uint64_t refine_budget = quality_preset(Quality::Default).refine_budget;  // --refine-budget (0: none)
  uint32_t refine_ray_budget = quality_preset(Quality::Default).refine_ray_budget;  // --refine-ray-budget
  uint64_t refine_by_check = 0;                                             // --refine-by-check (0: none)
  std::string depfile;
  bool metadata_timings = false;
  std::string sh_format = "f32";
  std::string atlas_format = "auto";
  std::string irradiance_atlas = "on";  // --irradiance-atlas on|off (the level's unless given)
  int depth_tile = quality_preset(Quality::Default).depth_tile;  // --depth-tile 16|8|4 (the level's unless given)
  std::string voxels;  // --voxels FILE.vdb
  float voxel_size = 0.f;
  int32_t voxel_res = 0;
  std::string voxel_sdf = "on";
  bool lpv = false;  // --lpv: light propagation volume cascades into --out
  // --lpv-res, --lpv-iterations, --lpv-cascades, --lpv-samples (vpl_samples); the rest is set by
  // to_lpv_settings.
  LpvSettings lpv_settings;
  std::string report;  // --report report.html
  std::string leak_audit = "on";
  // --reconstruction-check: after a DDGI bake, the reconstructed irradiance at surface points
  // against path-traced references (bake/preview/reconstruction_check.h).
  std::string reconstruction_check = "on";
  uint32_t check_patches = 128, check_rays = 128;
  float check_noise = 0.03f;      // --check-noise
  uint32_t check_ray_budget = 0;  // --check-ray-budget (0: 32 x --check-rays on a device, 4 x on the CPU)
  // --check-camera (repeatable): the check's patches from these views instead of the probes' view
  // (cli/check_camera.h); --check-fov their vertical field of view (0: the glTF camera's, else 50).
  std::vector<std::string> check_cameras;
  float check_fov = 0.f;
  std::string shard;  // --shard I/N: bake only shard I of N of the probes into a shard file
  std::vector<std::string> from_shards;  // --from-shards: finish a --refine-by-check bake from its shards
  VxgiArgs vxgi;  // --vxgi and its options (cli/vxgi_stage.h)
};

// The bake command's description and options, under the headings --help shows (cli/help.h).
void add_bake_options(CLI::App& sub, BakeArgs& a);
bool parse_precision(const std::string& text, FloatPrecision& out);
// The GPU BVH cache's folder: --cache-dir, else $GIBAKE_CACHE_DIR, else $XDG_CACHE_HOME/gibake, else
// $HOME/.cache/gibake; "off" (or no home at all): none (empty).
std::string resolve_cache_dir(const std::string& option);
// --shard I/N (0 <= I < N <= 65536).
Status parse_shard(const std::string& text, uint32_t& index, uint32_t& count);
// The options a quality level sets, which win over it when given.
extern const std::vector<std::string> kQualityOptions;
// --quality as a level; a bad word gets the one-line error with the nearest level.
Status parse_quality_option(const std::string& text, Quality& out);
// The level, then the options given over it, then every other option.
Status to_settings(const BakeArgs& a, DdgiSettings& s);
// The summary's line on the level (bake/ddgi/quality.h quality_text); `spacing`: the default grid's.
std::string quality_summary(const BakeArgs& a, const DdgiSettings& s, const VolumeSettings& v, float spacing);
Status to_voxel_settings(const BakeArgs& a, VoxelSettings& v);
// --probe-volume, --default-volume, --detail-volumes (bake/ddgi/volumes.h).
Status to_volume_settings(const BakeArgs& a, VolumeSettings& v);
// A --refine-ray-budget above what the grid's probes take (with_ray_budget, bake/ddgi/ddgi.h:
// refined probes average at most the bake's rays) is refused, not traced as the grid's.
Status check_refine_ray_budget(const BakeArgs& a, const DdgiSettings& s, const VolumeSettings& v);
// `backend` as to_settings parsed it into DdgiSettings::backend.
LpvSettings to_lpv_settings(const BakeArgs& a, const BackendSettings& backend);

}  // namespace gibake::cli
