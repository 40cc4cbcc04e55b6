// The DDGI bake's host memory estimate (bake/ddgi/ddgi_memory.h): per-ray records are counted only
// where the route keeps them, so the figure follows the chosen gather and backend.
#include <gtest/gtest.h>

#include "bake/ddgi/bounce.h"
#include "bake/ddgi/ddgi_memory.h"
#include "kernels/integrate.h"
#include "kernels/shade.h"

namespace gibake {
namespace {

DdgiMemoryShape shape(Gather gather) {
  DdgiMemoryShape s;
  s.probes = 1000;
  s.sh_coefficients = 9;
  s.irradiance_texels = 1000 * 100;
  s.depth_texels = 1000 * 324;
  s.gather = gather;
  s.rays = 256;
  s.max_rays = 2048;
  s.ray_budget = 1024;
  return s;
}

TEST(DdgiMemory, PathGatherKeepsNoRecordsProbesGatherKeepsItsBounceHits) {
  const DdgiMemory path = estimate_ddgi_memory(shape(Gather::Path));
  const DdgiMemory probes = estimate_ddgi_memory(shape(Gather::Probes));
  EXPECT_EQ(path.records, 0u);
  // One bounce hit a ray of the probe's one batch, and each probe's list.
  EXPECT_EQ(probes.records, 1000u * (256u * sizeof(BounceHit) + 24u));
  EXPECT_GT(probes.total(), path.total() + probes.records);  // also the depth tiles the passes read
}

TEST(DdgiMemory, AdaptiveRecordsAreKeptOnTheHostUnlessTheDeviceKeepsTheStatistics) {
  DdgiMemoryShape s = shape(Gather::Path);
  s.adaptive = true;
  EXPECT_EQ(kept_rays_per_probe(s), 640u);  // the first batch and half of the budget beyond it
  EXPECT_EQ(estimate_ddgi_memory(s).records, 1000u * 640u * sizeof(kernels::HitRecord));
  s.probe_lights = true;  // each record with its paired emitter sample
  EXPECT_EQ(estimate_ddgi_memory(s).records,
            1000u * 640u * (sizeof(kernels::HitRecord) + sizeof(kernels::RaySample)));
  s.vulkan = true;
  EXPECT_EQ(estimate_ddgi_memory(s).records, 0u);
  // A device whose passes cannot keep them (no 64-bit floats, accumulators over its largest
  // buffer) hands the records to the host, as the CPU keeps them.
  s.vulkan_host_records = true;
  EXPECT_EQ(estimate_ddgi_memory(s).records, 1000u * 640u * (sizeof(kernels::HitRecord) + sizeof(kernels::RaySample)));
  s.vulkan_host_records = false;
  s.ray_budget = 0;  // no budget: half of the cap beyond the first batch
  s.vulkan = false;
  EXPECT_EQ(kept_rays_per_probe(s), 256u + (2048u - 256u) / 2);
  s.ray_budget = 100;  // a budget under one batch: the first batch alone
  EXPECT_EQ(kept_rays_per_probe(s), 256u);
}

TEST(DdgiMemory, ProbesAndAtlasesGrowWithTheGrid) {
  DdgiMemoryShape s = shape(Gather::Path);
  const DdgiMemory small = estimate_ddgi_memory(s);
  s.probes *= 2;
  s.irradiance_texels *= 2;
  s.depth_texels *= 2;
  EXPECT_EQ(estimate_ddgi_memory(s).probes, 2 * small.probes);
  // The atlases alone: RGBA float irradiance, RG float depth.
  EXPECT_GE(small.probes, 1000u * (100u * 16u + 324u * 8u));
  // The probe filter writes a second SH array and irradiance atlas beside the first.
  DdgiMemoryShape f = shape(Gather::Path);
  f.probe_filter = true;
  EXPECT_EQ(estimate_ddgi_memory(f).probes, small.probes + 1000u * (9u * 3u * 4u + 100u * 16u));
}

TEST(DdgiMemory, TheFitsSecondPassCountsItsFileCopyAndKeptHits) {
  DdgiMemoryShape s = shape(Gather::Path);
  s.fit_points = 5000;
  const uint64_t one = estimate_ddgi_memory(s).fit;
  s.fit_second_pass = true;  // a device ends the paths again: a second file and the baked atlases
  const uint64_t device = estimate_ddgi_memory(s).fit;
  const uint64_t file = ddgi_file_bytes(s.probes, s.sh_coefficients, s.irradiance_texels,
                                        coarse_depth_texels(s.depth_texels, s.depth_tile));
  EXPECT_GE(device - one, file + s.irradiance_texels * 16u);
  s.fit_kept_hits = fit_kept_hits(20000, 262144, 144);  // the CPU keeps the paths' first hits, 24 bytes each
  EXPECT_EQ(s.fit_kept_hits, 5000u * 144u);             // a quarter of the directions find a point
  EXPECT_EQ(estimate_ddgi_memory(s).fit - device, 5000u * 144u * 24u);
  EXPECT_EQ(fit_kept_hits(4000000, 262144, 144), 262144u * 144u);  // at most the points the fit takes
}

}  // namespace
}  // namespace gibake
