#include "bake/ddgi/probe_integrate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>

#include "bake/ddgi/classify.h"
#include "io/bakefile/bake_stream.h"
#include "kernels/sh.h"

namespace gibake {
namespace {

using kernels::HitRecord;

bool reflects(const HitRecord& h) {
  return h.kind() == kernels::kHitFront && (h.albedo[0] > 0.f || h.albedo[1] > 0.f || h.albedo[2] > 0.f);
}

}  // namespace

ProbeIntegrator::ProbeIntegrator(const ProbeIntegrateConfig& config, DdgiResult& result)
    : config_(config), result_(result) {
  const size_t n = size_t(config.probe_count);
  coefs_ = kernels::sh_coefficient_count(config.sh_order);
  result.stats.resize(n);
  cone_ = kernels::build_depth_cone_table(kDepthTexels);
  texel_dirs_ = kernels::oct_tile_directions(kIrradianceTexels);
  if (config.depth_atlas) {
    result.depth_width = config.depth_layout.width();
    result.depth_height = config.depth_layout.height();
  }
  // The large zeroed arrays side by side: each costs its pages' first touch, hundreds of MB on large
  // grids (docs/BENCHMARKS.md).
  const size_t atlas_values = size_t(result.depth_width) * result.depth_height * 2;
  const kernels::AtlasLayout& irr = config.irradiance_layout;
  tbb::parallel_invoke(
      [&] {
        if (config.depth_atlas) result.depth_atlas.assign(atlas_values, 0.f);
      },
      [&] {
        if (config.zero_irradiance_atlas) result.irradiance_atlas.assign(size_t(irr.width()) * irr.height() * 4, 0.f);
      },
      [&] {
        if (config.depth_tiles) depth_tiles.assign(n * kDepthTile * kDepthTile * 2, 0.f);
      },
      [&] { sh0.assign(n * coefs_ * 3, 0.f); }, [&] { irradiance.assign(n * kIrradianceTile, 0.f); });
  if (tiles_at_finish()) finished_.reset(new std::atomic<uint8_t>[n]());
  inactive.assign(n, 0);
  enclosed.assign(n, 0);
  sky_only.assign(n, 0);
  probe_rays.assign(n, 0);
  bounce_hits.resize(n);
}

kernels::RaySample ProbeIntegrator::integration_sample(const float dir_t[4], int kind, const float radiance[3],
                                                       float max_distance) {
  float depth = dir_t[3];
  if (kind == kernels::kHitMiss)
    depth = max_distance;
  else if (kind == kernels::kHitBack)
    depth *= 0.9f;  // DDGI's rule: pull back-face hits in
  depth = std::min(depth, max_distance);
  return {{dir_t[0], dir_t[1], dir_t[2], depth}, {radiance[0], radiance[1], radiance[2], 0.f}};
}

void ProbeIntegrator::set_stats(int32_t p, size_t n, const TraceCounters& counters, double relative_error) {
  DdgiProbeStats& ps = result_.stats[slot(p)];
  const float max_distance = config_.max_distance;
  ps.rays = static_cast<uint32_t>(n + (*config_.relocation_rays)[p]);
  ps.relative_error = static_cast<float>(relative_error);
  ps.nearest_front = counters.nearest_front < 0.f ? max_distance : counters.nearest_front;
  ps.backface_fraction = n == 0 ? 0.f : float(counters.back_faces) / float(n);
  probe_rays[slot(p)] = static_cast<uint32_t>(n);
}

void ProbeIntegrator::finish(int32_t p, const ProbeRayTest& test, const TraceCounters& counters, double relative_error,
                             const ProbeIntegrals& integrals) {
  finish_tested(p, test, counters, relative_error, integrals);
  tiles_done(p);
}

void ProbeIntegrator::finish(int32_t p, const HitRecord* h, size_t n, const TraceCounters& counters,
                             double relative_error, const ProbeIntegrals* integrals, const kernels::RaySample* lights) {
  finish_records(p, h, n, counters, relative_error, integrals, lights);
  tiles_done(p);
}

void ProbeIntegrator::finish_tested(int32_t p, const ProbeRayTest& test, const TraceCounters& counters,
                                    double relative_error, const ProbeIntegrals& integrals) {
  set_stats(p, test.rays, counters, relative_error);
  ray_test(p, test);
  write_depth_tile(p, integrals.depth);
  if (!inactive[slot(p)]) copy_integrals(p, integrals);  // inactive probes keep zero SH and irradiance
}

void ProbeIntegrator::copy_integrals(int32_t p, const ProbeIntegrals& integrals) {
  std::copy(integrals.sh, integrals.sh + coefs_ * 3, &sh0[slot(p) * coefs_ * 3]);
  std::copy(integrals.irradiance, integrals.irradiance + kIrradianceTile, &irradiance[slot(p) * kIrradianceTile]);
}

void ProbeIntegrator::finish_records(int32_t p, const HitRecord* h, size_t n, const TraceCounters& counters,
                                     double relative_error, const ProbeIntegrals* integrals,
                                     const kernels::RaySample* lights) {
  const float max_distance = config_.max_distance;
  set_stats(p, n, counters, relative_error);
  ray_test(p, ray_test_counts(h, n));
  if (integrals) {
    write_depth_tile(p, integrals->depth);
    if (inactive[slot(p)]) return;  // inactive probes keep zero SH and irradiance
    if (config_.keep_bounce_hits) keep_bounces(p, h, n);
    copy_integrals(p, *integrals);
    return;
  }
  std::vector<kernels::RaySample>& samples = samples_.local();
  samples.resize(lights ? 2 * n : n);
  kernels::RaySample* rs = samples.data();
  for (size_t r = 0; r < n; ++r) rs[r] = integration_sample(h[r].dir_t, h[r].kind(), h[r].radiance0, max_distance);
  integrate_depth_tile(p, rs, n);
  if (inactive[slot(p)]) return;  // inactive probes keep zero SH and irradiance
  if (config_.keep_bounce_hits) keep_bounces(p, h, n);
  for (size_t r = 0; r < n; ++r) {
    for (int a = 0; a < 4; ++a) rs[r].dir_depth[a] = h[r].dir_t[a];
    for (int a = 0; a < 4; ++a) rs[r].radiance[a] = h[r].radiance0[a];
  }
  // The paired emitter samples follow the rays, under the rays' norm 4pi/n.
  if (lights) std::copy(lights, lights + n, rs + n);
  // Irradiance texels of pass 0 are kept and completed by the last pass.
  kernels::integrate_radiance(texel_dirs_.data(), kIrradianceTexels, rs, static_cast<int>(lights ? 2 * n : n),
                              config_.sh_order, &sh0[slot(p) * coefs_ * 3], &irradiance[slot(p) * kIrradianceTile],
                              static_cast<int>(n));
}

ProbeRayTest ray_test_counts(const HitRecord* h, size_t n) {
  ProbeRayTest t;
  t.rays = n;
  for (size_t r = 0; r < n; ++r) {
    t.misses += h[r].kind() == kernels::kHitMiss;
    t.saw_light = t.saw_light || h[r].radiance0[0] > 0.f || h[r].radiance0[1] > 0.f || h[r].radiance0[2] > 0.f;
  }
  return t;
}

void ProbeIntegrator::ray_test(int32_t p, const ProbeRayTest& test) {
  // The ray test of classify_probes (which repeats it and adds the closed-mesh check).
  inactive[slot(p)] = result_.stats[slot(p)].backface_fraction > config_.backface_threshold;
  // Enclosed space no light reaches (inside closed shapes, sealed dark rooms): every ray met
  // geometry and none brought light back, and the voxel grid's flood fill from outside cannot reach
  // the probe. (Rays alone cannot tell a sealed box from a dark corner of an open building, where
  // an inactive probe would let its lit neighbours leak light onto dark walls.)
  const size_t n = test.rays, misses = test.misses;
  const bool saw_light = test.saw_light;
  sky_only[slot(p)] = n > 0 && misses == n;
  if (!inactive[slot(p)] && n > 0 && misses == 0 && !saw_light && config_.voxels) {
    const kernels::float3 pos = config_.position(p);
    const float at[3] = {pos.x, pos.y, pos.z};
    if (probe_in_enclosed_space(*config_.voxels, at)) inactive[slot(p)] = enclosed[slot(p)] = 1;
  }
}

bool ProbeIntegrator::write_irradiance_tile(int32_t p, const kernels::AtlasLayout& layout, DdgiResult& result) const {
  int ox, oy;
  layout.tile_origin(config_.first_probe + p, ox, oy);
  const float* irr = &irradiance[size_t(p) * kIrradianceTile];
  const int width = layout.width();
  bool lit = false;
  for (int y = 0; y < kIrradianceTexels; ++y)
    for (int x = 0; x < kIrradianceTexels; ++x) {
      float* t = &result.irradiance_atlas[(size_t(oy + 1 + y) * size_t(width) + ox + 1 + x) * 4];
      for (int c = 0; c < 3; ++c) {
        t[c] = irr[(y * kIrradianceTexels + x) * 3 + c];
        lit = lit || t[c] > 0.f;
      }
      t[3] = 1.f;
    }
  kernels::oct_fill_border(result.irradiance_atlas.data(), width, 4, ox, oy, kIrradianceTexels);
  return lit;
}

bool ProbeIntegrator::write_irradiance_atlas(const kernels::AtlasLayout& layout, DdgiResult& result) const {
  result.irradiance_width = layout.width();
  result.irradiance_height = layout.height();
  const size_t values = size_t(result.irradiance_width) * result.irradiance_height * 4;
  const kernels::AtlasLayout& zeroed = config_.irradiance_layout;
  const bool was_zeroed = config_.zero_irradiance_atlas && zeroed.res == layout.res &&
                          zeroed.width() == layout.width() && zeroed.height() == layout.height() &&
                          result.irradiance_atlas.size() == values;
  if (!was_zeroed) result.irradiance_atlas.assign(values, 0.f);
  // Tiles written as their probes finished stay (the same texels; a stream may be reading them).
  const bool keep_finished = was_zeroed && tiles_at_finish();
  // Each probe writes its own bordered tile: the tiles do not overlap, so any split gives the same bytes.
  std::atomic<bool> any_light{keep_finished && lit_at_finish_.load()};
  tbb::parallel_for(
      tbb::blocked_range<int32_t>(0, config_.probe_count, 256), [&](const tbb::blocked_range<int32_t>& r) {
        bool lit = false;
        for (int32_t p = r.begin(); p < r.end(); ++p)
          if (!keep_finished || !finished_[size_t(p)].load(std::memory_order_acquire))
            lit = write_irradiance_tile(p, layout, result) || lit;
        if (lit) any_light.store(true, std::memory_order_relaxed);
      });
  return any_light.load();
}

bool ProbeIntegrator::any_irradiance() const {
  std::atomic<bool> lit{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, irradiance.size(), size_t(1) << 16),
                    [&](const tbb::blocked_range<size_t>& r) {
                      if (lit.load(std::memory_order_relaxed)) return;
                      for (size_t i = r.begin(); i < r.end(); ++i)
                        if (irradiance[i] > 0.f) {
                          lit.store(true, std::memory_order_relaxed);
                          return;
                        }
                    });
  return lit.load();
}

void ProbeIntegrator::tiles_done(int32_t p) {
  if (!tiles_at_finish()) return;
  if (write_irradiance_tile(slot(p), config_.irradiance_layout, result_)) lit_at_finish_.store(true);
  finished_[slot(p)].store(1, std::memory_order_release);
  if (!stream_) return;
  const kernels::AtlasLayout* layouts[2] = {&config_.irradiance_layout, &config_.depth_layout};
  for (int atlas = 0; atlas < 2; ++atlas) {
    int ox, oy;
    layouts[atlas]->tile_origin(p, ox, oy);
    const int tile = layouts[atlas]->tile();
    // The last of a tile row's probes to finish tells the stream (acq_rel: every tile of the row
    // written before).
    if (probes_left_[atlas][size_t(oy / tile)].fetch_sub(1, std::memory_order_acq_rel) == 1)
      stream_->rows_final(BakeFileStream::Atlas(atlas), oy, oy + tile);
  }
}

void ProbeIntegrator::set_stream(BakeFileStream* stream) {
  if (!stream || !tiles_at_finish() || !config_.depth_atlas || config_.first_probe != 0) return;
  DdgiFileShape shape;
  shape.probes = uint64_t(config_.probe_count);
  shape.sh_values = uint64_t(config_.probe_count) * uint64_t(coefs_) * 3;
  shape.irradiance_width = config_.irradiance_layout.width();
  shape.irradiance_height = config_.irradiance_layout.height();
  shape.depth_width = result_.depth_width;
  shape.depth_height = result_.depth_height;
  stream->open(shape, result_.irradiance_atlas.data(), result_.depth_atlas.data());
  if (!stream->active()) return;
  // Each tile row's probe count, counted down as its probes finish.
  const kernels::AtlasLayout* layouts[2] = {&config_.irradiance_layout, &config_.depth_layout};
  for (int atlas = 0; atlas < 2; ++atlas) {
    const kernels::AtlasLayout& layout = *layouts[atlas];
    std::vector<int32_t> count(size_t(layout.height() / layout.tile()), 0);
    for (int32_t p = 0; p < config_.probe_count; ++p) {
      int ox, oy;
      layout.tile_origin(p, ox, oy);
      ++count[size_t(oy / layout.tile())];
    }
    probes_left_[atlas].reset(new std::atomic<int32_t>[count.size()]);
    for (size_t r = 0; r < count.size(); ++r) probes_left_[atlas][r].store(count[r], std::memory_order_relaxed);
  }
  stream_ = stream;
}

void ProbeIntegrator::refine_state(int32_t p, ProbeState& state) const {
  if (enclosed[slot(p)])
    state = ProbeState::Inactive;
  else if (sky_only[slot(p)] && state == ProbeState::Active)
    state = ProbeState::SkyOnly;
}

void ProbeIntegrator::integrate_depth_tile(int32_t p, const kernels::RaySample* rs, size_t n) {
  float interior[kDepthTexels * kDepthTexels * 2];
  kernels::integrate_depth(cone_, rs, static_cast<int>(n), interior);
  write_depth_tile(p, interior);
}

void ProbeIntegrator::write_depth_tile(int32_t p, const float* interior) {
  float own[kDepthTile * kDepthTile * 2];  // without depth_tiles: bordered here, then into the atlas
  float* tile = config_.depth_tiles ? &depth_tiles[slot(p) * kDepthTile * kDepthTile * 2] : own;
  for (int y = 0; y < kDepthTexels; ++y)
    for (int x = 0; x < kDepthTexels; ++x)
      for (int c = 0; c < 2; ++c)
        tile[((y + 1) * kDepthTile + x + 1) * 2 + c] = interior[(y * kDepthTexels + x) * 2 + c];
  kernels::oct_fill_border(tile, kDepthTile, 2, 0, 0, kDepthTexels);
  if (!config_.depth_atlas) return;
  int ox, oy;
  config_.depth_layout.tile_origin(p, ox, oy);
  for (int y = 0; y < kDepthTile; ++y)
    std::copy(tile + y * kDepthTile * 2, tile + (y + 1) * kDepthTile * 2,
              &result_.depth_atlas[(size_t(oy + y) * result_.depth_width + ox) * 2]);
}

void ProbeIntegrator::keep_bounces(int32_t p, const HitRecord* h, size_t n) {
  std::vector<BounceHit>& bh = bounce_hits[slot(p)];
  bh.reserve(size_t(std::count_if(h, h + n, reflects)));
  for (size_t r = 0; r < n; ++r)
    if (reflects(h[r]))
      bh.push_back(BounceHit{{h[r].dir_t[0], h[r].dir_t[1], h[r].dir_t[2], h[r].dir_t[3]},
                             {h[r].normal_kind[0], h[r].normal_kind[1], h[r].normal_kind[2]},
                             {h[r].albedo[0], h[r].albedo[1], h[r].albedo[2]}});
}

BounceInputs make_bounce_inputs(const DdgiResult& result, const BounceParams& params, const ProbeIntegrator& integ,
                                const std::vector<float>& positions) {
  BounceInputs bi;
  for (int a = 0; a < 3; ++a) {
    bi.volume.grid_min[a] = result.desc.grid_min[a];
    bi.volume.spacing[a] = result.desc.spacing[a];
    bi.volume.counts[a] = result.desc.counts[a];
  }
  bi.volume.params[0] = params.normal_bias;
  bi.volume.params[1] = params.smooth_backface;
  bi.volume.offsets = result.offsets.data();
  bi.volume.inactive = integ.inactive.data();
  bi.volume.depth_atlas = result.depth_atlas.data();
  bi.volume.depth_tiles = integ.depth_tiles.empty() ? nullptr : integ.depth_tiles.data();
  bi.volume.depth_width = result.depth_width;
  bi.volume.atlas_planes_per_row = result.atlas_planes_per_row;
  bi.volume.depth_res = kDepthTexels;
  bi.sh0 = &integ.sh0;
  bi.hits = &integ.bounce_hits;
  bi.probe_rays = integ.probe_rays.data();
  bi.texel_dirs = integ.texel_dirs().data();
  bi.sh_order = result.desc.sh_order;
  bi.bounces = params.bounces;
  bi.energy_conservation = params.energy_conservation;
  bi.positions = positions.data();
  return bi;
}

}  // namespace gibake
