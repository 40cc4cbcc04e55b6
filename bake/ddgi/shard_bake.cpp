// Handing a shard's probes over (see shard_bake.h).
#include "bake/ddgi/shard_bake.h"

#include <algorithm>

#include "kernels/octahedral.h"

namespace gibake {

std::vector<int32_t> shard_probe_list(const DdgiShardRun* shard, int32_t probe_count) {
  ShardRange r{0, 1, 0, uint32_t(probe_count)};
  if (shard) r = volume_shard_range(*shard, uint32_t(probe_count));
  std::vector<int32_t> probes;
  probes.reserve(r.end - r.begin);
  for (uint32_t p = r.begin; p < r.end; ++p) probes.push_back(int32_t(p));
  return probes;
}

void shard_integrator_config(const DdgiShardRun* shard, int32_t probe_count, ProbeIntegrateConfig& config) {
  if (!shard) return;
  const ShardRange r = volume_shard_range(*shard, uint32_t(probe_count));
  config.first_probe = int32_t(r.begin);
  config.probe_count = int32_t(r.end - r.begin);
  config.depth_atlas = false;
}

namespace {

// Probe p, the i-th of the shard (the integrator's and result.stats' index i).
void copy_probe(const ShardHandOff& h, const DdgiResult& result, int32_t p, DdgiShard& out, size_t i) {
  const ProbeIntegrator& integ = *h.integ;
  DdgiShardProbe& q = out.probes[i];
  for (int a = 0; a < 3; ++a) q.offset[a] = (*h.offsets)[size_t(p) * 3 + a];
  q.inactive = integ.inactive[i];
  q.enclosed = integ.enclosed[i];
  q.sky_only = integ.sky_only[i];
  q.moved = (*h.moved)[p];
  q.stats = result.stats[i];
  q.integrated_rays = integ.probe_rays[i];
  q.bounce_hits = uint32_t(integ.bounce_hits[i].size());
  const TraceCounters& c = (*h.counters)[p];
  q.primary_rays = c.rays;
  q.shadow_rays = c.shadow_rays;
  q.bounce_rays = c.bounce_rays;
  q.relocation_rays = (*h.relocation_rays)[p];
  const size_t coefs = size_t(result.desc.sh_coefficients()) * 3;
  const size_t irr = size_t(ProbeIntegrator::kIrradianceTile);
  const size_t depth = size_t(kShardDepthTile) * kShardDepthTile * 2;
  std::copy_n(&integ.sh0[i * coefs], coefs, &out.sh0[i * coefs]);
  std::copy_n(&integ.irradiance[i * irr], irr, &out.irradiance[i * irr]);
  std::copy_n(&integ.depth_tiles[i * depth], depth, &out.depth_tiles[i * depth]);
  for (const BounceHit& b : integ.bounce_hits[i]) {
    out.bounce_hits.insert(out.bounce_hits.end(), b.dir_t, b.dir_t + 4);
    out.bounce_hits.insert(out.bounce_hits.end(), b.normal, b.normal + 3);
    out.bounce_hits.insert(out.bounce_hits.end(), b.albedo, b.albedo + 3);
  }
}

}  // namespace

Status hand_off_shard(const DdgiSettings& s, const ShardHandOff& h, const DdgiShardRun& run, DdgiResult& result,
                      DdgiReport& report) {
  DdgiShard& out = *run.out;
  const ShardRange r = volume_shard_range(run, uint32_t(result.desc.probe_count()));
  // The ray test's states and the closed-mesh check over the shard's probes (result.stats holds them).
  ray_test_states(result.stats, s.backface_threshold, result.states);
  if (h.check->started()) {
    const double waited = h.check->wait();
    report.stage_seconds.emplace_back("closed-mesh check wait", waited);
    const std::vector<float> positions(h.positions->begin() + ptrdiff_t(r.begin) * 3,
                                       h.positions->begin() + ptrdiff_t(r.end) * 3);
    const ClassifyReport cr = h.closed_check->report(positions, result.stats, result.states);
    out.closed_checked = cr.closed_mesh_checked;
    out.closed_inside = cr.inside_by_cgal;
    out.closed_inside_but_active = cr.disagreements;
    out.closed_inactive_outside = cr.inactive_outside_closed;
  }
  out.range = r;
  out.first_block = run.first_block;
  out.total_blocks = run.total_blocks ? run.total_blocks : probe_blocks(uint32_t(result.desc.probe_count()));
  out.desc = result.desc;
  out.atlas_planes_per_row = result.atlas_planes_per_row;
  kernels::AtlasLayout irr, depth;  // the complete bake's atlases
  for (int a = 0; a < 3; ++a) irr.counts[a] = depth.counts[a] = result.desc.counts[a];
  irr.res = kIrradianceTexels;
  depth.res = kDepthTexels;
  irr.planes_per_row = depth.planes_per_row = result.atlas_planes_per_row;
  out.irradiance_width = irr.width();
  out.irradiance_height = irr.height();
  out.depth_width = depth.width();
  out.depth_height = depth.height();
  out.probe_gather = s.gather == Gather::Probes;
  const size_t n = r.end - r.begin;
  out.probes.assign(n, {});
  out.sh0.assign(n * size_t(result.desc.sh_coefficients()) * 3, 0.f);
  out.irradiance.assign(n * size_t(ProbeIntegrator::kIrradianceTile), 0.f);
  out.depth_tiles.assign(n * size_t(kShardDepthTile) * kShardDepthTile * 2, 0.f);
  out.bounce_hits.clear();
  report.probes = int32_t(n);
  for (size_t i = 0; i < n; ++i) {
    const int32_t p = int32_t(r.begin + i);
    copy_probe(h, result, p, out, i);
    const DdgiShardProbe& q = out.probes[i];
    report.inactive += q.inactive;
    report.enclosed += q.enclosed;
    report.sky_only += !q.inactive && q.sky_only;
    report.active += !q.inactive && !q.sky_only;
    report.relocated += q.moved;
    report.primary_rays += q.primary_rays;
    report.shadow_rays += q.shadow_rays;
    report.bounce_rays += q.bounce_rays;
    report.relocation_rays += q.relocation_rays;
    report.bounce_hits += q.bounce_hits;
  }
  return Status::ok();
}

}  // namespace gibake
