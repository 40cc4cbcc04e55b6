// The pipeline's parts (bake/pipeline/bake_request.h): the stages up to the results, then the files
// with the checks that run beside their write.
#pragma once
#include "bake/pipeline/bake_request.h"

namespace gibake {

// Import -> voxelize (+ the LPV's geometry) -> DDGI volumes (+ the leak audit when it is not beside
// the write) -> LPV -> voxel GI -> the .vdb.
Status run_bake_stages(const BakeRequest& r, const Context& ctx, BakeResult& run);

// After the stages: the device session closes beside the rest; the leak audit and the
// reconstruction check run beside the bake file's write; the depfile.
Status finish_bake(const BakeRequest& r, const Context& ctx, BakeResult& run);

// Every kind's settings as the bake file records them (its input hash covers them).
std::string bake_file_settings_json(const BakeRequest& r, const BakeResult& run);

// Thin walls between lit and unlit space, against the probe grid's coarsest spacing: warnings only
// where the bake's active probes blend across one (most light first), every region for the
// summary, the JSON and the report. `seconds` gets its time (the caller records it: beside the
// write, run.timings is the write's).
Status run_leak_audit(const BakeRequest& r, const Context& ctx, BakeResult& run, double& seconds);
// The leak warnings weigh the final probe states, which a shard does not have (the merge makes them).
bool leak_audit_wanted(const BakeRequest& r, const BakeResult& run);
// The audit reads the voxels, the scene and the final states, and the bake file does not record it:
// it runs beside the write and the reconstruction check, except with metadata timings, whose
// timings in the file include it.
inline bool leak_audit_beside_write(const BakeRequest& r) { return !r.metadata_timings; }

}  // namespace gibake
