// The DDGI bake's host working set, estimated from its shape before anything is allocated, so that
// a bake over the memory cap is refused up front. It counts what the chosen route really holds: the
// scene and what the set-up builds from it, the per-probe arrays and atlases every bake keeps, and
// the per-ray records that only some routes keep (adaptive batches on the host until a probe is
// finished; the probe-feedback gather's bounce hits until the last pass), and what stays until the
// file is written: the writer encodes the whole file in one buffer, and a bake of several volumes
// keeps every volume's result until then.
#pragma once
#include <cstdint>

#include "bake/ddgi/ddgi.h"

namespace gibake {

struct DdgiMemoryShape {
  uint64_t probes = 0;
  // Of them, those never traced (a near volume's probes far from surfaces, DdgiSettings::
  // near_surface_reach): they keep their per-probe arrays and atlas tiles but no ray records.
  uint64_t left_out = 0;
  int sh_coefficients = 9;
  uint64_t irradiance_texels = 0, depth_texels = 0;  // atlas areas, width x height, as baked
  int depth_tile = kDepthTexels;  // DdgiSettings::depth_tile: the file's tiles; fewer add the coarse atlas
  Gather gather = Gather::Path;
  uint32_t rays = 0, max_rays = 0, ray_budget = 0;
  bool adaptive = false;      // target_error > 0: batches' records kept until a probe is finished
  bool probe_lights = false;  // each record has a paired emitter sample (path gather with emitters or a sky map)
  // The Vulkan backend: with the path gather the adaptive statistics stay on the device (no records
  // kept on the host); its trace chunks are staged through host memory.
  bool vulkan = false;
  // ... except where the device cannot keep them (DdgiDevice::keeps_records_on_host): then the
  // records stay on the host as on the CPU.
  bool vulkan_host_records = false;
  bool probe_filter = false;  // DdgiSettings::filter: a filtered copy of the SH and irradiance atlas
  // Points the surface fit may trace (DdgiSettings::fit, after every volume; 0: off): its sparse
  // rows, their transpose and the points' path sums, held once the trace's records are gone.
  uint64_t fit_points = 0;
  // Tables through which the fit's ended paths read the probes (CachedProbeField), one a thread.
  uint32_t fit_read_tables = 0;
  // A second pass of the fit (SurfaceFitSettings::passes): a second encoding of the volumes and a
  // copy of the atlases before the fit; and the first hits the CPU keeps for it (0 where a device
  // traces the paths again instead): fit_kept_hits().
  bool fit_second_pass = false;
  uint64_t fit_kept_hits = 0;
  uint64_t scene_bytes = 0;  // scene_host_bytes
  // The other volumes of the bake (their results and their part of the file), held beside this one.
  uint64_t held_bytes = 0;
};

// The first hits a fit keeps for its second pass: a hit a path of each point its probes' directions
// find. A direction finds a surface within its reach about one time in four (the rest meet open
// space, or surfaces beyond it), so that share of `directions` (the probes' rays), at most
// `max_points`, times `paths`.
uint64_t fit_kept_hits(uint64_t directions, uint64_t max_points, uint32_t paths);

struct DdgiMemory {
  uint64_t scene = 0;    // the process, the scene, its BVH, texture mips and voxel grids
  uint64_t probes = 0;   // per-probe arrays and the atlases
  uint64_t records = 0;  // kept hit records and bounce hits
  uint64_t file = 0;     // this volume's sections in the write buffer
  uint64_t held = 0;     // DdgiMemoryShape::held_bytes
  uint64_t fit = 0;      // the surface fit's working set, after the records are freed
  uint64_t total() const { return scene + probes + (records > fit ? records : fit) + file + held; }
};

// A volume's sections as the writer encodes them with the default formats (f32 SH, f16 atlases):
// its share of the write buffer. Atlas areas in texels (width x height).
uint64_t ddgi_file_bytes(uint64_t probes, int sh_coefficients, uint64_t irradiance_texels, uint64_t depth_texels);
// What a finished volume keeps until the file is written, its result (SH, offsets, states,
// statistics and the f32 atlases) and its part of the file, from its probe count alone (the
// atlases' tiles without the wrap's spare rows); `irradiance_atlas` and `depth_tile` as DdgiSettings.
uint64_t ddgi_held_bytes(uint64_t probes, int sh_coefficients, bool irradiance_atlas, int depth_tile);
// An atlas area of kDepthTexels tiles in tiles of `depth_tile` interior texels, same layout.
uint64_t coarse_depth_texels(uint64_t depth_texels, int depth_tile);

// Rays a probe's records are counted for: one batch, or with target_error the first batch and half
// of what the ray budget (or the cap) allows beyond it.
uint64_t kept_rays_per_probe(const DdgiMemoryShape& shape);
DdgiMemory estimate_ddgi_memory(const DdgiMemoryShape& shape);
// The scene's arrays and textures and what the set-up derives from them (BVH, mips, enclosure
// voxels), with the process's own footprint.
uint64_t scene_host_bytes(const Scene& scene, int32_t enclosure_resolution);

}  // namespace gibake
