// One shard of a split DDGI bake (`gibake bake --shard I/N`). Everything up to the end of the trace
// is per probe (relocation, rays keyed by (seed, probe, pass, ray), adaptive batches, depth moments,
// pass-0 SH and texels, the ray test and the enclosure test), so a shard runs bake_ddgi's stages for
// its probe range only and hands over what its probes hold at that point. What reads other probes
// (the probe-feedback bounce passes: 8-probe weights over pass k-1's SH and the depth atlas) or all
// of them (atlases, probe counts, the "bake is black" check, the file) is left to the merge
// (shard_merge.h), which runs it on the assembled probes exactly as bake_ddgi would.
#pragma once
#include <cstdint>
#include <vector>

#include "bake/ddgi/classify.h"
#include "bake/ddgi/ddgi.h"
#include "bake/ddgi/probe_integrate.h"
#include "bake/run/arena.h"
#include "io/results/ddgi_shard.h"

namespace gibake {

// The shard a bake bakes and where it leaves it (RunContext::shard): range.index of range.count.
// bake_ddgi_volumes (bake/ddgi/volumes.h) fills `volumes_out`, one shard per volume, and hands
// bake_ddgi each volume with `out` and where its blocks lie among the bake's (shard_range).
struct DdgiShardRun {
  ShardRange range;
  uint32_t first_block = 0, total_blocks = 0;  // 0, 0: a bake of one volume
  DdgiShard* out = nullptr;
  std::vector<DdgiShard>* volumes_out = nullptr;
};

// The probes of a volume of `probes` probes that the shard owns.
inline ShardRange volume_shard_range(const DdgiShardRun& run, uint32_t probes) {
  return shard_range(run.range.index, run.range.count, probes, run.first_block, run.total_blocks);
}

// The probe indices a bake traces: the shard's range, or every probe.
std::vector<int32_t> shard_probe_list(const DdgiShardRun* shard, int32_t probe_count);
// A shard's integrator holds its range only, without a depth atlas, so that a shard's memory
// divides with N like its time; nothing changes without a shard.
void shard_integrator_config(const DdgiShardRun* shard, int32_t probe_count, ProbeIntegrateConfig& config);

// bake_ddgi's state once every probe of the shard is traced (the integrator and result.stats hold
// the shard's range only; the rest is indexed by global probe).
struct ShardHandOff {
  const std::vector<float>* positions = nullptr;  // every probe, rest + offset
  const std::vector<float>* offsets = nullptr;
  const std::vector<uint8_t>* moved = nullptr;
  const std::vector<uint64_t>* relocation_rays = nullptr;
  const std::vector<TraceCounters>* counters = nullptr;
  const ProbeIntegrator* integ = nullptr;
  BesideTask* check = nullptr;  // the closed-mesh check's build (waited for here)
  const ClosedMeshCheck* closed_check = nullptr;
};

// Copies the shard's probes into run.out (grid, per-probe data, closed-mesh sums over its probes)
// and fills `report` for the shard's probes (counts, rays, stage seconds).
Status hand_off_shard(const DdgiSettings& s, const ShardHandOff& h, const DdgiShardRun& run, DdgiResult& result,
                      DdgiReport& report);

}  // namespace gibake
