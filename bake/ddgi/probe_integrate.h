// Finishing a probe once all its rays are traced (the trace stage's per-probe work, shared by the
// CPU and GPU trace paths): its statistics, the ray-test state (back faces, enclosed space, sky
// only), depth moments into its atlas tile, pass-0 SH and irradiance texels, and the compact list of
// hits the probe-feedback bounce passes re-shade. Every probe writes only its own slots, so the
// results do not depend on which thread finishes which probe.
#pragma once
#include <tbb/enumerable_thread_specific.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bake/ddgi/bounce.h"
#include "bake/trace/probe_rays.h"
#include "io/results/ddgi_result.h"
#include "kernels/integrate.h"
#include "kernels/octahedral.h"

namespace gibake {

struct VoxelGrid;
class BakeFileStream;

struct ProbeIntegrateConfig {
  int32_t probe_count = 0;
  // The integrator holds probes [first_probe, first_probe + probe_count): a shard's range (its
  // per-probe arrays and result.stats indexed from first_probe), else 0 and the whole grid.
  int32_t first_probe = 0;
  bool depth_atlas = true;  // false (a shard): depth moments in depth_tiles only, no result.depth_atlas
  // false: no depth_tiles, the moments go straight into the atlas (a whole bake with the path
  // gather: no bounce pass reads them, so their per-probe copy is not worth its memory).
  // depth_atlas or depth_tiles must hold.
  bool depth_tiles = true;
  int sh_order = 2;
  float max_distance = 0.f;  // depth of misses
  float backface_threshold = 0.25f;
  bool keep_bounce_hits = false;      // probe-feedback gather: keep the hits the bounce passes re-shade
  const VoxelGrid* voxels = nullptr;  // enclosure test; null: none
  kernels::AtlasLayout depth_layout;
  // A whole bake's irradiance atlas (irradiance_layout): zeroed here, beside the other arrays, instead
  // of by write_irradiance_atlas after the trace, so its first touch runs in parallel with the others.
  bool zero_irradiance_atlas = false;
  kernels::AtlasLayout irradiance_layout;
  std::function<kernels::float3(int32_t probe)> position;
  const std::vector<uint64_t>* relocation_rays = nullptr;  // per probe, counted into its stats
};

// Welford's running mean and variance of a probe's ray luminances, in ray order (probe_stats.comp
// runs the same recurrence on the device).
struct RunningStats {
  uint64_t n = 0;
  double mean = 0.0, m2 = 0.0;
  void add(double x) {
    ++n;
    const double d = x - mean;
    mean += d / double(n);
    m2 += d * (x - mean);
  }
  double relative_error() const {
    if (n < 2 || mean <= 0.0) return 0.0;
    return std::sqrt(m2 / double(n - 1) / double(n)) / mean;
  }
};

// What the ray test reads of a probe's rays: how many, how many missed, whether any brought light.
struct ProbeRayTest {
  size_t rays = 0;
  size_t misses = 0;
  bool saw_light = false;
};
ProbeRayTest ray_test_counts(const kernels::HitRecord* h, size_t n);

// A probe's integrals computed elsewhere (the Vulkan kernel, bake/vulkan/integrate.h) in the layouts of
// integrate_radiance and integrate_depth: SH, irradiance texels, unbordered depth moments.
struct ProbeIntegrals {
  const float* sh = nullptr;
  const float* irradiance = nullptr;
  const float* depth = nullptr;
};

class ProbeIntegrator {
 public:
  static constexpr int kDepthTile = kDepthTexels + 2;
  static constexpr int kIrradianceTile = kIrradianceTexels * kIrradianceTexels * 3;

  // Sizes the per-probe arrays and result.stats / depth_atlas (result.depth_width/height set here).
  ProbeIntegrator(const ProbeIntegrateConfig& config, DdgiResult& result);

  // A probe that is never traced (DdgiSettings::near_surface_reach): inactive, zero SH and light.
  void leave_out(int32_t p) { inactive[slot(p)] = 1; }

  // `n` records of probe p; `relative_error` of its luminance estimate. With `integrals`, its SH,
  // texels and depth moments come from there (computed from integration_sample of the same records)
  // instead of the CPU kernels; statistics and states are the same either way.
  // `lights` (optional, n): the rays' paired emitter samples (trace_probe_paths), integrated with
  // them into the SH and texels (not the depth moments or the ray test), unless `integrals` holds
  // the result already.
  void finish(int32_t p, const kernels::HitRecord* h, size_t n, const TraceCounters& counters, double relative_error,
              const ProbeIntegrals* integrals = nullptr, const kernels::RaySample* lights = nullptr);
  // The same from statistics reduced elsewhere (bake/vulkan/probe_stats.h) instead of records: the
  // same states; no bounce hits can be kept (keep_bounce_hits must be off).
  void finish(int32_t p, const ProbeRayTest& test, const TraceCounters& counters, double relative_error,
              const ProbeIntegrals& integrals);
  // What the integration reads of a ray record: its direction, the depth for visibility (misses at
  // the max distance, back faces pulled in by 0.9, clamped) and its radiance.
  static kernels::RaySample integration_sample(const float dir_t[4], int kind, const float radiance[3],
                                               float max_distance);
  float max_distance() const { return config_.max_distance; }
  // The enclosure voxels, when they are built after the integrator (before any probe finishes).
  void set_enclosure_voxels(const VoxelGrid* voxels) { config_.voxels = voxels; }

  // Irradiance texels of every probe into result's atlas (bordered tiles; alpha 1), probes side by
  // side in the calling arena; the atlas is zeroed first unless the constructor zeroed it for this
  // layout, and tiles written as their probes finished (tiles_at_finish) are kept. True when any
  // texel holds light.
  bool write_irradiance_atlas(const kernels::AtlasLayout& layout, DdgiResult& result) const;
  // True when any probe's irradiance tile holds light: what write_irradiance_atlas answers, for a
  // bake that keeps no irradiance atlas (DdgiSettings::irradiance_atlas).
  bool any_irradiance() const;
  // A whole bake's path gather (no bounce pass changes a finished probe's texels) writes each
  // probe's irradiance tile into the atlas as it finishes, beside its depth tile.
  bool tiles_at_finish() const { return config_.zero_irradiance_atlas && !config_.keep_bounce_hits; }
  // The bake file written as the atlases' rows become final (io/bakefile/bake_stream.h): opened here
  // with the atlases' shape and told of final rows as probes finish. Before any probe finishes; a
  // whole bake's path gather only (else nothing streams).
  void set_stream(BakeFileStream* stream);
  // A probe's final state from classification's and the ray test's: enclosed -> Inactive, an
  // active probe that saw only sky -> SkyOnly.
  void refine_state(int32_t p, ProbeState& state) const;

  // Per probe held (index p - first_probe), read by the later stages.
  std::vector<float> depth_tiles;  // kDepthTile^2 x (mean, mean^2), bordered; empty unless config.depth_tiles
  std::vector<float> sh0;          // pass-0 SH, coefficients x RGB
  std::vector<float> irradiance;   // texels x RGB (pass 0; completed by the bounce passes)
  std::vector<uint8_t> inactive, enclosed, sky_only;
  std::vector<uint32_t> probe_rays;
  std::vector<std::vector<BounceHit>> bounce_hits;
  const std::vector<float>& texel_dirs() const { return texel_dirs_; }

 private:
  void finish_tested(int32_t p, const ProbeRayTest& test, const TraceCounters& counters, double relative_error,
                     const ProbeIntegrals& integrals);
  void finish_records(int32_t p, const kernels::HitRecord* h, size_t n, const TraceCounters& counters,
                      double relative_error, const ProbeIntegrals* integrals, const kernels::RaySample* lights);
  // After every finish: the irradiance tile (tiles_at_finish), the probe marked finished, the stream
  // told of rows that became final.
  void tiles_done(int32_t p);
  // Slot p's bordered irradiance tile into result's atlas; true when it holds light.
  bool write_irradiance_tile(int32_t p, const kernels::AtlasLayout& layout, DdgiResult& result) const;
  // The ray test of classify_probes and the enclosure test: sets inactive, enclosed, sky_only.
  void ray_test(int32_t p, const ProbeRayTest& test);
  // Where probe p's values are in the per-probe arrays and result.stats.
  size_t slot(int32_t p) const { return size_t(p - config_.first_probe); }
  // Statistics every finish writes.
  void set_stats(int32_t p, size_t n, const TraceCounters& counters, double relative_error);
  void integrate_depth_tile(int32_t p, const kernels::RaySample* rs, size_t n);
  void write_depth_tile(int32_t p, const float* interior);
  // SH and irradiance texels computed elsewhere into the probe's slots.
  void copy_integrals(int32_t p, const ProbeIntegrals& integrals);
  void keep_bounces(int32_t p, const kernels::HitRecord* h, size_t n);

  ProbeIntegrateConfig config_;
  DdgiResult& result_;
  int coefs_ = 0;
  kernels::DepthConeTable cone_;
  std::vector<float> texel_dirs_;
  tbb::enumerable_thread_specific<std::vector<kernels::RaySample>> samples_;
  // tiles_at_finish: which slots finished (their tiles written), whether any of those held light.
  std::unique_ptr<std::atomic<uint8_t>[]> finished_;
  std::atomic<bool> lit_at_finish_{false};
  // The stream, and per atlas (irradiance, depth) each tile row's probes not finished yet.
  BakeFileStream* stream_ = nullptr;
  std::unique_ptr<std::atomic<int32_t>[]> probes_left_[2];
};

// What the bounce passes read of the settings (bounces 0: the path gather, no passes).
struct BounceParams {
  float normal_bias = 0.f, smooth_backface = 0.f;
  int bounces = 0;
  float energy_conservation = 1.f;
};

// The bounce passes' inputs over integrated probes, the same for a whole bake and for a merge of
// shards: the grid, result.offsets, the integrator's states, depth tiles, pass-0 results and
// bouncing hits, the depth atlas, and `positions` (probe_count x 3, where the probes' rays left).
BounceInputs make_bounce_inputs(const DdgiResult& result, const BounceParams& params, const ProbeIntegrator& integ,
                                const std::vector<float>& positions);

}  // namespace gibake
