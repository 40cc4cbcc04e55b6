// Refinement by the bake's own check (--refine-by-check; bake/ddgi/refine.h): once every volume is
// baked, the reconstruction check (bake/preview/reconstruction_check.h) runs on them as the file
// will hold them, from what the probes see; the bricks holding the points of the patches it finds
// off by more than its tolerance, beyond the reference's own noise (which its second pass lowers
// where the patches are noisy, --check-noise), get refined volumes, which are then baked on the
// same set-up and device. The file's own check runs after, on every volume.
#pragma once
#include "bake/pipeline/bake_request.h"
#include "bake/run/run_context.h"

namespace gibake {

// After the DDGI stage of a whole bake (not a shard): nothing when r.volumes.check_budget is 0 or
// the bake has no default grid. `shared`: the run context the volumes were baked with (its
// platform still alive); run.prepared, run.lod and run.gpu hold the set-up.
Status refine_by_check(const BakeRequest& r, const Context& ctx, const RunContext& shared, BakeResult& run);

// The baked volumes as the file will hold them (the writer's encoding), for the runtime loader.
Status encode_baked_volumes(const BakeRequest& r, const BakeResult& run, std::vector<uint8_t>& bytes);

// The points of the patches a check found off: a patch misses when |baked / reference - 1| exceeds
// settings.within by more than the reference's relative standard error; each of its points carries
// that |ratio - 1|. Patches below the check's floor are left out, as the check leaves them out.
std::vector<CheckMiss> check_misses(const ReconstructionReference& reference, const ReconstructionError& error,
                                    const ReconstructionSettings& settings);

}  // namespace gibake
