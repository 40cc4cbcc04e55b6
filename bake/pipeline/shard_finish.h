// A sharded bake that refines by check (`gibake bake ... --refine-by-check N`): the shards bake the
// planned volumes (`--shard I/N`); the pass reads every probe and the scene, so the bake's own
// command finishes it with `--from-shards PART...` in place of `--shard`. That run sets up, places
// and plans every volume as the one-go bake does but traces none of their probes (it runs as a
// shard that owns none), takes the probes from the parts (bake/ddgi/shard_merge.h), and then runs
// the pass and writes the file: the one-go bake's bytes.
#pragma once
#include "bake/pipeline/bake_request.h"

namespace gibake {

// The shard run of a finishing bake: past the last shard, it owns no probe of any volume.
DdgiShardRun no_probes_shard_run(std::vector<DdgiShard>& volumes_out);

// After bake_ddgi_volumes of the finishing run: reads and finishes the parts into run.volumes and
// ends the shard run (run.shard_run, shared.shard), so that what follows is the one-go bake's.
// InvalidInput naming a part made from another scene, other settings or another gibake than this
// command (the input hash) or of another volume plan.
Status take_volumes_from_shards(const BakeRequest& r, const Context& ctx, RunContext& shared, BakeResult& run);

}  // namespace gibake
