#include "bake/ddgi/ddgi_memory.h"

#include <algorithm>

#include "bake/ddgi/bounce.h"
#include "bake/scene/triangle_shading.h"
#include "bake/trace/kept_hits.h"
#include "bake/trace/probe_field_cache.h"
#include "io/results/ddgi_result.h"
#include "kernels/integrate.h"
#include "kernels/shade.h"

namespace gibake {

namespace {

// The executable, its libraries and the thread pools before any scene.
constexpr uint64_t kProcessBytes = uint64_t(48) << 20;
// Per triangle, what the set-up derives: the Embree BVH, the prepared per-triangle arrays and the
// packed shading record a hit reads.
constexpr uint64_t kSetupBytesPerTriangle = 256 + sizeof(TriangleShading);
// Per enclosure voxel: the voxel grid's channels and the flood fill's marks.
constexpr uint64_t kBytesPerEnclosureVoxel = 8;
// The Vulkan trace's chunks staged on the host: records and emitter samples of about 2^21 rays,
// two chunks in flight.
constexpr uint64_t kVulkanStagingBytes = 2 * (uint64_t(1) << 21) * (sizeof(kernels::HitRecord) + sizeof(kernels::RaySample));

template <class T>
uint64_t bytes_of(const std::vector<T>& v) {
  return uint64_t(v.capacity()) * sizeof(T);
}

// A probe's SH, offset, state and statistics: as the result holds them and as the file stores
// them with the default formats (f32 SH, u8 state).
uint64_t probe_record_bytes(int sh_coefficients) {
  return uint64_t(sh_coefficients) * 3 * sizeof(float) + 3 * sizeof(float) + 1 + sizeof(DdgiProbeStats);
}

// What every probe holds whatever the route: the result's SH, offset, state and statistics, the
// integrator's pass-0 SH and irradiance texels, the bake's positions, relocation and counters,
// the trace's running statistics.
uint64_t per_probe_bytes(const DdgiMemoryShape& s) {
  const uint64_t sh = uint64_t(s.sh_coefficients) * 3 * sizeof(float);
  const uint64_t texels = uint64_t(kIrradianceTexels) * kIrradianceTexels * 3 * sizeof(float);
  uint64_t b = probe_record_bytes(s.sh_coefficients);                 // result
  b += sh + texels + 3 + sizeof(uint32_t) + 24 + 1;                   // integrator
  b += sizeof(int32_t) + 3 * sizeof(float) + sizeof(uint64_t) + 1 + 32 + 3 * sizeof(float);  // bake
  b += 24 + (s.adaptive ? 48 : 0);                                    // running statistics, kept lists
  if (s.gather == Gather::Probes) {
    const uint64_t tile = uint64_t(kDepthTexels + 2) * (kDepthTexels + 2) * 2 * sizeof(float);
    b += tile + 2 * (sh + texels);  // depth tiles the passes read; each pass's SH and texels
  }
  return b;
}

}  // namespace

uint64_t kept_rays_per_probe(const DdgiMemoryShape& s) {
  if (!s.adaptive) return s.rays;
  const uint64_t cap = std::max(s.max_rays, s.rays);
  const uint64_t most = s.ray_budget ? std::min<uint64_t>(cap, std::max(s.rays, s.ray_budget)) : cap;
  // Every probe keeps its first batch; of what the budget (or cap) allows beyond it, half: probes
  // stop once under the target error, often long before the budget, so the whole of it would
  // overstate most bakes as far as it understates those that spend it all.
  return s.rays + (most - s.rays) / 2;
}

DdgiMemory estimate_ddgi_memory(const DdgiMemoryShape& s) {
  DdgiMemory m;
  m.scene = s.scene_bytes + (s.vulkan ? kVulkanStagingBytes : 0);
  // The baked atlas, and beside it the coarse one the file gets when --depth-tile is below the bake's.
  const uint64_t file_depth_texels = coarse_depth_texels(s.depth_texels, s.depth_tile);
  const uint64_t coarse_copy = s.depth_tile == kDepthTexels ? 0 : file_depth_texels;
  m.probes = s.probes * per_probe_bytes(s) + s.irradiance_texels * 4 * sizeof(float) +
             (s.depth_texels + coarse_copy) * 2 * sizeof(float);
  if (s.probe_filter)  // the filter writes its output beside the values it reads
    m.probes += s.probes * uint64_t(s.sh_coefficients) * 3 * sizeof(float) + s.irradiance_texels * 4 * sizeof(float);
  const uint64_t rays = kept_rays_per_probe(s);
  const uint64_t traced = s.probes - std::min(s.left_out, s.probes);
  // Adaptive batches keep their records (and paired emitter samples) on the host, except where the
  // device keeps the path gather's statistics itself.
  if (s.adaptive && !(s.vulkan && s.gather == Gather::Path && !s.vulkan_host_records)) {
    const uint64_t record = sizeof(kernels::HitRecord) + (s.probe_lights ? sizeof(kernels::RaySample) : 0);
    m.records += traced * rays * record;
  }
  // The probe-feedback passes re-shade every reflecting hit: at most one a ray.
  if (s.gather == Gather::Probes) m.records += traced * (rays * sizeof(BounceHit) + 24);
  m.file = ddgi_file_bytes(s.probes, s.sh_coefficients, s.irradiance_texels, file_depth_texels);
  m.held = s.held_bytes;
  // A point reads about 32 texels (8 probes x 4): 8-byte entries in the rows and in their
  // transpose; its surface, path sums and sample beside them.
  m.fit = s.fit_points * (32 * 16 + 200);
  // The volumes as the fit reads them: their file sections and probe-major copies of the atlases
  // without the irradiance's alpha (loader::LoadOptions::probe_major_tiles).
  const uint64_t fit_file = m.file + s.irradiance_texels * 3 * 2 + file_depth_texels * 2 * 2;
  if (s.fit_points) m.fit += fit_file;
  // The second pass: the fitted volumes encoded beside the baked ones, the baked atlases kept, and
  // the paths' first hits (fit_kept_hits) with each point's record.
  if (s.fit_points && s.fit_second_pass)
    m.fit += fit_file + s.irradiance_texels * 4 * sizeof(float) + s.fit_points * sizeof(EndedPathHits::Point);
  m.fit += s.fit_kept_hits * sizeof(EndedPathHits::Hit);
  m.fit +=
      uint64_t(s.fit_read_tables) * CachedProbeField::table_bytes(CachedProbeField::table_bits_for(s.fit_read_tables));
  return m;
}

uint64_t fit_kept_hits(uint64_t directions, uint64_t max_points, uint32_t paths) {
  return std::min(max_points, directions / 4) * paths;
}

uint64_t ddgi_file_bytes(uint64_t probes, int sh_coefficients, uint64_t irradiance_texels, uint64_t depth_texels) {
  return probes * probe_record_bytes(sh_coefficients) + irradiance_texels * 4 * 2 + depth_texels * 2 * 2;
}

uint64_t coarse_depth_texels(uint64_t depth_texels, int depth_tile) {
  const uint64_t full = uint64_t(kDepthTexels + 2) * (kDepthTexels + 2);
  return depth_texels / full * uint64_t(depth_tile + 2) * uint64_t(depth_tile + 2);
}

uint64_t ddgi_held_bytes(uint64_t probes, int sh_coefficients, bool irradiance_atlas, int depth_tile_texels) {
  const uint64_t irradiance_tile = uint64_t(kIrradianceTexels + 2) * (kIrradianceTexels + 2);
  const uint64_t depth_tile = uint64_t(depth_tile_texels + 2) * (depth_tile_texels + 2);
  const uint64_t irradiance_texels = irradiance_atlas ? probes * irradiance_tile : 0,
                 depth_texels = probes * depth_tile;
  const uint64_t result = probes * probe_record_bytes(sh_coefficients) + irradiance_texels * 4 * sizeof(float) +
                          depth_texels * 2 * sizeof(float);
  return result + ddgi_file_bytes(probes, sh_coefficients, irradiance_texels, depth_texels);
}

uint64_t scene_host_bytes(const Scene& scene, int32_t enclosure_resolution) {
  uint64_t b = kProcessBytes + bytes_of(scene.positions) + bytes_of(scene.normals) + bytes_of(scene.uvs) +
               bytes_of(scene.colors) + bytes_of(scene.indices) + bytes_of(scene.tri_material);
  for (const Texture& t : scene.textures) b += bytes_of(t.rgba8) * 4 / 3;  // with its mip chain
  b += uint64_t(scene.triangle_count()) * kSetupBytesPerTriangle;
  const uint64_t r = uint64_t(std::max(enclosure_resolution, 0));
  return b + r * r * r * kBytesPerEnclosureVoxel;
}

}  // namespace gibake
