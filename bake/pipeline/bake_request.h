// One call runs a whole bake request: import, the stages of every kind asked for (voxels, DDGI
// volumes, LPV, voxel GI) in their order, the leak audit and the reconstruction check, and the files
// (the bake file or a shard file, the .vdb, the depfile). The front end turns its arguments into a
// BakeRequest and prints what comes back; progress, notes and warnings reach it through the
// Context's callbacks, never by the library printing.
#pragma once
#include <cstdint>
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/shard_bake.h"
#include "bake/ddgi/volumes.h"
#include "bake/lpv/lpv.h"
#include "bake/preview/preview.h"
#include "bake/preview/reconstruction_check.h"
#include "bake/run/arena.h"
#include "bake/run/backend.h"
#include "bake/scene/prepare.h"
#include "bake/scene/texture_lod.h"
#include "bake/voxel/leak_audit.h"
#include "bake/voxel/leak_probes.h"
#include "bake/voxel/voxelize.h"
#include "bake/vxgi/vxgi.h"
#include "io/bakefile/bake_file.h"
#include "io/bakefile/bake_stream.h"
#include "io/bakefile/input_digest.h"
#include "io/context.h"
#include "io/results/lpv_result.h"
#include "io/results/vxgi_result.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct GpuSession;

// A view the reconstruction check takes its patches from, or one --near-camera places probes for:
// the preview settings of one spec (`spec` names it in errors).
struct CheckView {
  std::string spec;
  PreviewSettings settings;
};

// The files a bake reads and writes.
struct BakeFiles {
  std::string scene;       // the glTF file
  std::string out;         // the bake file (or the shard file); empty: the .vdb alone
  std::string voxels_out;  // the .vdb of the voxel grids; empty: none
  std::string depfile;     // a make-style depfile of the outputs; empty: none
};

// The reconstruction check after a DDGI bake (bake/preview/reconstruction_check.h).
struct CheckRequest {
  bool enabled = true;
  uint32_t patches = 128, rays = 128;
  float target_noise = 0.03f;    // ReconstructionSettings::target_noise (--check-noise)
  uint32_t ray_budget = 0;       // ReconstructionSettings::ray_budget (--check-ray-budget; 0: the default)
  std::vector<CheckView> views;  // empty: patches from the probes' view
  int width = 320, height = 180;  // the views' size, split into 8x8-pixel blocks
};

// What to bake and where to write it; every setting already checked by the caller.
struct BakeRequest {
  BakeFiles files;
  bool ddgi = false, lpv = false, vxgi = false;
  DdgiSettings ddgi_settings;  // also the lights and sky of every other kind
  VolumeSettings volumes;
  VoxelSettings voxels;  // the --voxels grid, also the LPV's geometry volume
  LpvSettings lpv_settings;
  VxgiSettings vxgi_settings;
  BakeFileOptions file_options;  // storage formats (the writer's callbacks are the pipeline's)
  unsigned threads = 0;          // for the file's metadata and the writer; the arena is ctx.threads
  bool metadata_timings = false;  // timings in the file's metadata (the leak audit then runs before the write)
  bool leak_audit = true;
  CheckRequest check;
  // --near-camera: views whose surfaces get a view volume each (bake/ddgi/view_volume.h), resolved
  // into the run's VolumeSettings::views right after the import.
  std::vector<CheckView> near_views;
  bool shard = false;  // bake only shard `shard_index` of `shard_count` into a shard file
  uint32_t shard_index = 0, shard_count = 0;
  // --from-shards: the shard files of this very bake, whose probes the run takes instead of tracing
  // them, then refines by check and writes the bake file (bake/pipeline/shard_finish.h).
  std::vector<std::string> from_shards;
};

// What a bake leaves for the caller's summary and report. Held behind a pointer: the caller frees
// it beside the device's close (bake/run/arena.h, ReleaseBeside).
struct BakeResult {
  Scene scene;
  std::unique_ptr<PreparedScene> prepared;  // one Embree scene for every stage
  bool have_voxels = false;
  VoxelGrid voxels;
  VoxelReport voxel_report;
  // The DDGI volumes (bake/ddgi/volumes.h): the first is the one the leak audit, the summary's probe
  // counts and the report describe (the default grid unless --default-volume off).
  std::vector<BakedVolume> volumes = std::vector<BakedVolume>(1);
  std::string volume_rule;  // what the automatic detail-volume rule found
  std::string refine_rule;  // what refinement placed (bake/ddgi/refine.h)
  VolumeSettings volume_settings;
  // Several volumes or a customised request: the file's metadata, the summary and the report list them.
  bool list_volumes() const { return volumes.size() > 1 || volume_settings.customised(); }
  DdgiResult& ddgi() { return volumes[0].result; }
  const DdgiResult& ddgi() const { return volumes[0].result; }
  DdgiReport& ddgi_report() { return volumes[0].report; }
  const DdgiReport& ddgi_report() const { return volumes[0].report; }
  LpvResult lpv;
  VxgiResult vxgi;
  bool have_leak_audit = false;
  LeakAudit leaks;                     // every region
  std::vector<LeakExposure> exposure;  // per region: the bake's active probes across it
  std::vector<std::pair<std::string, double>> timings;
  VulkanWarmup vulkan_warmup;       // --ddgi on Vulkan: the device opening while the scene imports
  TextureLod lod;                   // the bake's texture mips, for the reconstruction check
  std::shared_ptr<GpuSession> gpu;  // the DDGI bake's device session, shared with the LPV (one context a process)
  SharedClosedMeshes closed_meshes;  // found once for every DDGI volume's closed-mesh check
  BackendChoice backend;            // where the DDGI bake ran, when it had a device session
  bool had_session = false;
  bool have_reconstruction = false;
  bool have_surface_fit = false;
  SurfaceFitReport surface_fit;              // --surface-fit: what the fit did
  std::vector<PreviewCamera> check_cameras;  // the request's check views, resolved right after the import
  ReconstructionError reconstruction;
  std::vector<DdgiShard> shards;  // shard bake: this shard's probes of each volume, for the shard file
  DdgiShardRun shard_run;         // shard_run.volumes_out set for a shard bake
  // The scene's content and files hashed beside the stages (the file's input hash adds the settings
  // at the end); it reads `scene`, which nothing changes after the import, and its destructor waits.
  // Shared: a --from-shards run reads it before the write too.
  std::shared_future<std::pair<Status, InputDigest>> input_digest;
  // Its encoding reads the volumes' atlases (bake_stream.h): after them, so that it goes first.
  std::unique_ptr<BakeFileStream> file_stream;
  // The device session, closed on a thread of its own once no stage needs it; last, so that it is
  // joined before anything above goes.
  ReleaseBeside closing_session;
};

// Runs `request` to its written files. `out` is made afresh; on failure it holds what was done.
Status run_bake(const BakeRequest& request, const Context& ctx, std::unique_ptr<BakeResult>& out);

}  // namespace gibake
