/* gibake bake file format (.gibake / probes.bin), version 1.5. Plain C; usable from C and C++.
 *
 * Layout (all integers and floats little-endian, IEEE 754):
 *   [file header, 64 bytes][section table: section_count x 64 bytes][sections, each 16-aligned]
 * Every section's bytes are covered by an XXH64 (seed 0) checksum in its table entry; the header
 * carries an XXH64 of itself (checksum field zeroed) and one of the section table.
 * Readers reject an unknown major version and skip sections of unknown type (by offset/size).
 * Full description: docs/FORMAT.md. */
#ifndef GIBAKE_FORMAT_H
#define GIBAKE_FORMAT_H

#include <stddef.h>
#include <stdint.h>

#define GIBAKE_MAGIC_BYTES "GIBAKE\0\x1a" /* 8 bytes: 47 49 42 41 4B 45 00 1A */
#define GIBAKE_MAGIC_SIZE 8
#define GIBAKE_VERSION_MAJOR 1
#define GIBAKE_VERSION_MINOR 2
/* (1.3) Files that hold voxel-GI sections say minor 3; files without them keep minor 2, so bakes
 * without --vxgi stay byte-identical to those of earlier writers. */
#define GIBAKE_VERSION_MINOR_VXGI 3
/* (1.4) Files that hold a ddgi_volume_index (every file with two or more DDGI volumes) say minor 4;
 * files with one volume keep the minor they had, byte for byte. */
#define GIBAKE_VERSION_MINOR_INDEX 4
/* (1.5) Files that hold a sparse DDGI volume (GIBAKE_DDGI_FLAG_SPARSE) say minor 5; files without
 * one keep the minor they had, byte for byte. */
#define GIBAKE_VERSION_MINOR_SPARSE 5
#define GIBAKE_SECTION_ALIGNMENT 16
#define GIBAKE_HASH_SEED 0 /* XXH64 seed for every checksum in the file */

/* File header at offset 0. */
typedef struct gibake_file_header {
  uint8_t magic[8];              /* GIBAKE_MAGIC_BYTES */
  uint16_t version_major;        /* GIBAKE_VERSION_MAJOR; readers reject any other */
  uint16_t version_minor;        /* readers accept any minor of their major */
  uint32_t header_size;          /* bytes of this header; >= 64, later minors may grow it */
  uint32_t section_count;        /* entries in the section table */
  uint32_t flags;                /* reserved, 0 */
  uint64_t section_table_offset; /* byte offset of the table, 16-aligned */
  uint64_t file_size;            /* total bytes of the file */
  uint64_t input_hash;           /* XXH3-64 of scene files + settings + tool version (staleness) */
  uint64_t header_checksum;      /* XXH64 of header_size bytes with this field set to 0 */
  uint64_t table_checksum;       /* XXH64 of the section table (section_count * 64 bytes) */
} gibake_file_header;

/* One section table entry. */
typedef struct gibake_section_entry {
  uint32_t type;        /* gibake_section_type */
  uint32_t format;      /* gibake_element_format */
  uint64_t offset;      /* byte offset of the payload in the file, 16-aligned */
  uint64_t size;        /* payload bytes == count * element size (padding is not included) */
  uint64_t count;       /* number of elements */
  uint64_t checksum;    /* XXH64 of the size payload bytes */
  uint32_t group;       /* which volume the section belongs to (index of its volume section) */
  uint32_t flags;       /* reserved, 0 */
  uint64_t reserved[2]; /* 0 */
} gibake_section_entry;

typedef enum gibake_section_type {
  GIBAKE_SECTION_DDGI_VOLUME = 1,        /* gibake_ddgi_volume, format STRUCT, count 1 */
  GIBAKE_SECTION_DDGI_SH = 2,            /* F32 | F16, probe_count * sh_coefficients * 3 */
  GIBAKE_SECTION_DDGI_OFFSETS = 3,       /* F32X3, probe_count: relocation offsets, metres */
  GIBAKE_SECTION_DDGI_STATES = 4,        /* U8 | U32, probe_count: gibake_probe_state */
  GIBAKE_SECTION_DDGI_STATS = 5,         /* PROBE_STATS, probe_count: gibake_probe_stats */
  GIBAKE_SECTION_DDGI_IRRADIANCE = 6,    /* RGBA16F | RGBA32F | RGB9E5 (1.5), width*height texels, lux */
  GIBAKE_SECTION_DDGI_DEPTH = 7,         /* RG16F | RG32F, width*height texels: mean (m), mean^2 */
  GIBAKE_SECTION_METADATA = 8,           /* JSON (UTF-8 bytes, no terminator): settings, timings */
  GIBAKE_SECTION_LPV_CASCADE = 16,       /* (1.2) gibake_lpv_cascade, format STRUCT, count 1 */
  GIBAKE_SECTION_VXGI_VOLUME = 17,       /* (1.3) gibake_vxgi_volume, format STRUCT, count 1 */
  GIBAKE_SECTION_LPV_SH = 18,            /* (1.2) F32 | F16, cell_count * 12: [cell][R,G,B][4 SH], cd */
  GIBAKE_SECTION_VXGI_RADIANCE = 19,     /* (1.3) RGBA16F | RGBA32F, [level][face][z][y][x]: premultiplied */
  GIBAKE_SECTION_VXGI_SDF = 20,          /* (1.3) F16 | F32, level-0 cells: distance to an opaque voxel, m */
  GIBAKE_SECTION_DDGI_VOLUME_INDEX = 21, /* (1.4) U32: gibake_ddgi_volume_index + offsets + volume ids */
  GIBAKE_SECTION_DDGI_PROBE_SLOTS = 22,  /* (1.5) U32, probe_count: a sparse volume's stored index of each
                                            probe, or GIBAKE_PROBE_SLOT_NONE */
  /* 32..63: bake intermediates for gibake itself (a shard of a split bake, `gibake merge`), never
   * runtime data: runtime readers skip them as unknown types. docs/FORMAT.md, "Shard files". */
  GIBAKE_SECTION_SHARD_INFO = 32,       /* gibake_shard_info, format STRUCT, count 1 */
  GIBAKE_SECTION_SHARD_PROBES = 33,     /* gibake_shard_probe (STRUCT), one per probe of the range */
  GIBAKE_SECTION_SHARD_SH0 = 34,        /* F32, probes * sh_coefficients * 3: pass-0 SH */
  GIBAKE_SECTION_SHARD_IRRADIANCE = 35, /* F32, probes * 8*8 * 3: pass-0 irradiance texels */
  GIBAKE_SECTION_SHARD_DEPTH = 36,      /* F32, probes * 18*18 * 2: bordered depth-moment tiles */
  GIBAKE_SECTION_SHARD_BOUNCE_HITS = 37 /* F32, hits * 10: dir xyz, t, normal xyz, albedo rgb */
} gibake_section_type;

typedef enum gibake_element_format {
  GIBAKE_FORMAT_STRUCT = 1,       /* the section type's struct (size = sizeof that struct) */
  GIBAKE_FORMAT_F32 = 2,          /* 4 bytes */
  GIBAKE_FORMAT_F16 = 3,          /* 2 bytes, IEEE binary16 */
  GIBAKE_FORMAT_F32X3 = 4,        /* 12 bytes */
  GIBAKE_FORMAT_U8 = 5,           /* 1 byte */
  GIBAKE_FORMAT_U32 = 6,          /* 4 bytes */
  GIBAKE_FORMAT_RGBA16F = 7,      /* 8 bytes */
  GIBAKE_FORMAT_RGBA32F = 8,      /* 16 bytes */
  GIBAKE_FORMAT_RG16F = 9,        /* 4 bytes */
  GIBAKE_FORMAT_RG32F = 10,       /* 8 bytes */
  GIBAKE_FORMAT_PROBE_STATS = 11, /* gibake_probe_stats, 16 bytes */
  GIBAKE_FORMAT_JSON = 12,        /* 1 byte (UTF-8) */
  GIBAKE_FORMAT_RGB9E5 = 13       /* (1.5) 4 bytes: R, G, B 9-bit mantissas in bits 0-8, 9-17, 18-26 and a
                                     shared 5-bit exponent in 27-31; value = m * 2^(e - 24), 0..65408
                                     (Vulkan's E5B9G9R9_UFLOAT, GL_EXT_texture_shared_exponent) */
} gibake_element_format;

typedef enum gibake_units {
  GIBAKE_UNITS_NONE = 0,
  GIBAKE_UNITS_CANDELA_PER_M2 = 1, /* radiance (nits) */
  GIBAKE_UNITS_LUX = 2,            /* irradiance (lm/m^2) */
  GIBAKE_UNITS_CANDELA = 3         /* (1.2) radiant intensity (lm/sr): LPV cells */
} gibake_units;

typedef enum gibake_probe_state {
  GIBAKE_PROBE_ACTIVE = 0,   /* sampled */
  GIBAKE_PROBE_INACTIVE = 1, /* inside geometry or in enclosed space no light reaches: never sampled */
  GIBAKE_PROBE_SKY_ONLY = 2  /* (1.2) no ray met geometry; SH holds the sky; sampled like ACTIVE */
} gibake_probe_state;

/* DDGI volume description. Probe (x,y,z) has index x + X*(y + Y*z) and rest position
 * grid_min + (x,y,z)*spacing. Atlas: with k = atlas_planes_per_row, probe (x,y,z) is the tile at
 * column x + X*(y mod k), row z + Z*(y div k); a tile is (interior + 2*tile_border)^2 texels;
 * octahedral mapping with z as the hemisphere axis. Version 1.0 files have 0 there, meaning k = Y
 * (column x + X*y, row z).
 * (1.5) A sparse volume (flags & GIBAKE_DDGI_FLAG_SPARSE) stores only stored_probes of its probes:
 * its ddgi_probe_slots section gives each probe's slot (stored index, assigned in probe-index order)
 * or GIBAKE_PROBE_SLOT_NONE (not stored: inactive, never sampled). Its per-probe sections hold
 * stored_probes elements in slot order, and slot s is the atlas tile at column s mod T, row s div T,
 * T = atlas_tiles_per_row; atlas_planes_per_row is 0. */
#define GIBAKE_DDGI_FLAG_SPARSE 1u
#define GIBAKE_PROBE_SLOT_NONE 0xFFFFFFFFu
typedef struct gibake_ddgi_volume {
  float grid_min[3];          /* metres, world position of probe (0,0,0) */
  float grid_max[3];          /* metres, world position of probe (X-1,Y-1,Z-1) */
  float spacing[3];           /* metres, (grid_max-grid_min)/(counts-1); 0 on a 1-probe axis */
  float max_distance;         /* metres, depth recorded for ray misses */
  int32_t counts[3];          /* probes per axis, each >= 1 */
  uint32_t probe_count;       /* counts[0]*counts[1]*counts[2] */
  uint32_t sh_order;          /* 1 or 2 */
  uint32_t sh_coefficients;   /* (sh_order+1)^2 */
  uint32_t radiance_units;    /* GIBAKE_UNITS_CANDELA_PER_M2: SH of incident radiance */
  uint32_t irradiance_units;  /* GIBAKE_UNITS_LUX: irradiance atlas */
  uint32_t irradiance_tile;   /* interior texels per tile side (8) */
  uint32_t depth_tile;        /* interior texels per tile side (16) */
  uint32_t tile_border;       /* border texels per side (1) */
  uint32_t irradiance_width;  /* atlas texels; 0 when there is no irradiance atlas */
  uint32_t irradiance_height;
  uint32_t depth_width;       /* atlas texels; 0 when there is no depth atlas */
  uint32_t depth_height;
  uint32_t flags;                /* GIBAKE_DDGI_FLAG_*; other bits 0 */
  uint32_t atlas_planes_per_row; /* k, 1..Y: Y-planes of tiles side by side per band of rows; 0 when sparse */
  uint32_t stored_probes;        /* (1.5) sparse: probes stored, 1..probe_count; else 0 (unread) */
  uint32_t atlas_tiles_per_row;  /* (1.5) sparse: T, tiles per atlas row, 1..stored_probes; else 0 */
  uint32_t reserved[2];          /* 0 */
  float irradiance_scale;        /* (1.5) an RGB9E5 irradiance atlas's texels times this are lux (> 0, a
                                    power of two the writer picks so that sunlight fits); else 0, unread */
} gibake_ddgi_volume;

/* (1.2) One light propagation volume cascade. Cell (x,y,z) covers [grid_min + (x,y,z)*cell_size,
 * +cell_size), index x + X*(y + Y*z); its lpv_sh section (group = this section's table index)
 * holds 12 values per cell: for R, G, B the L1 SH (Y00, Y1-1 (y), Y10 (z), Y11 (x)) of the radiant
 * intensity I(w) (cd) of the light in the cell, w the direction the light travels. Irradiance for a
 * unit normal n: E(n) = [pi c0 Y00 + 2pi/3 sum_m c1m Y1m(-n)] / cell_size^2 (lux), trilinear over
 * cell centres. cascade_index 0 is the finest; each cascade is twice the extent of the previous. */
#define GIBAKE_LPV_FLAG_OCCLUSION 1u /* a geometry volume blocked propagation */
typedef struct gibake_lpv_cascade {
  float grid_min[3];         /* metres, min corner of cell (0,0,0) */
  float cell_size;           /* metres, > 0 */
  int32_t dims[3];           /* cells per axis, each >= 1 */
  uint32_t cell_count;       /* dims[0]*dims[1]*dims[2] */
  uint32_t cascade_index;    /* 0 = finest */
  uint32_t cascade_count;    /* cascades in the file */
  uint32_t iterations;       /* propagation steps accumulated */
  uint32_t sh_coefficients;  /* 4 (L1) */
  uint32_t units;            /* GIBAKE_UNITS_CANDELA */
  uint32_t flags;            /* GIBAKE_LPV_FLAG_*; other bits 0 */
  uint32_t reserved[2];      /* 0 */
} gibake_lpv_cascade;

/* (1.3) One voxel-GI volume (one clipmap level). Voxel (x,y,z) of mip level L covers
 * [grid_min + (x,y,z)*voxel_size*2^L, +voxel_size*2^L); level L has dims ceil(dims/2^L) per axis.
 * Its vxgi_radiance section (group = this section's table index) holds, level after level, face
 * after face (+X, -X, +Y, -Y, +Z, -Z), the voxels x-fastest as RGBA: rgb = alpha * L, where L is
 * the radiance (cd/m^2) leaving the voxel through that face (travelling towards +X for face +X,
 * i.e. what a viewer on the +X side sees) and alpha its opacity. Level L+1 face f is built from
 * level L by compositing, for each of the 4 child pairs along f's axis, the child nearer the
 * viewer of f over the other (front + (1 - front.a) * back), and averaging the 4 pairs. */
typedef struct gibake_vxgi_volume {
  float grid_min[3];        /* metres, min corner of voxel (0,0,0) */
  float voxel_size;         /* metres, > 0, level 0 */
  int32_t dims[3];          /* level-0 voxels per axis, each 1..4096 */
  uint32_t levels;          /* mip levels stored, 1..13, at most until every axis is 1 */
  uint32_t faces;           /* 6 */
  uint32_t clipmap_index;   /* 0 = finest */
  uint32_t clipmap_count;   /* clipmaps in the file */
  uint32_t units;           /* GIBAKE_UNITS_CANDELA_PER_M2 */
  float sky[3];             /* cd/m^2: radiance of cones that leave the volume unblocked */
  uint32_t flags;           /* 0 */
  float diffuse_scale;      /* > 0: factor on the diffuse cone set's irradiance, fitted by the bake
                               against its path tracer at calibration_points surface points */
  float calibration_error;  /* relative RMS of the scaled cone irradiance there (>= 0) */
  uint32_t calibration_points; /* 0: not calibrated (diffuse_scale 1) */
  uint32_t reserved;        /* 0 */
} gibake_vxgi_volume;

/* (1.4) Which DDGI volumes may weigh in where: a uniform grid of cubic cells over the union of the
 * volumes' regions (probe box grown by one spacing). The section is U32 words: this header (16
 * words), then cell_count + 1 offsets (offsets[0] = 0, non-decreasing, offsets[cell_count] =
 * id_count), then id_count volume ids. Cell (x,y,z), index x + X*(y + Y*z), covers [grid_min +
 * (x,y,z)*cell_size, +cell_size]; its ids are words offsets[c]..offsets[c+1] of the id array: the
 * file-order indices of the DDGI volumes whose region grown by cell_size/16 meets the closed cell,
 * in blend priority (finest spacing first, ties in file order). docs/FORMAT.md "Volume index". */
/* Several volumes: a volume whose weighed probes' largest back-face x visibility weight (before the
 * floor) is below this at a point takes that fraction of its blend weight there (docs/FORMAT.md
 * "Several volumes"). */
#define GIBAKE_DDGI_FULL_SIGHT 0.05f
#define GIBAKE_DDGI_INDEX_HEADER_WORDS 16u
#define GIBAKE_DDGI_INDEX_MAX_CELLS 65536u /* the writer's cap; readers accept up to 2^24 */
typedef struct gibake_ddgi_volume_index {
  float grid_min[3];      /* metres, min corner of cell (0,0,0) */
  float cell_size;        /* metres, > 0 */
  int32_t dims[3];        /* cells per axis, each >= 1 */
  uint32_t cell_count;    /* dims[0]*dims[1]*dims[2] */
  uint32_t volume_count;  /* the file's DDGI volumes (ids are below it) */
  uint32_t id_count;      /* volume ids after the offsets: the lists' total length */
  uint32_t longest;       /* the longest list */
  uint32_t flags;         /* 0 */
  uint32_t reserved[4];   /* 0 */
} gibake_ddgi_volume_index;

/* Per-probe bake statistics. */
typedef struct gibake_probe_stats {
  uint32_t rays;             /* rays traced for the probe over all passes */
  float relative_error;      /* estimated relative standard error of its irradiance */
  float nearest_front;       /* nearest front-face hit distance, metres */
  float backface_fraction;   /* fraction of rays that hit back faces */
} gibake_probe_stats;

/* Shard files: which shard of which bake a file holds. The volume is the complete bake's (its
 * atlas sizes those of the merged file); probes [probe_begin, probe_end) are this shard's. */
#define GIBAKE_SHARD_FLAG_BOUNCE_HITS 1u  /* the probe-feedback gather: hits for the merge's passes */
#define GIBAKE_SHARD_FLAG_GLOBAL 2u       /* this shard carries the bake's global volumes (LPV) */
#define GIBAKE_SHARD_FLAG_CLOSED_CHECKED 4u /* the closed-mesh check asked about some probe of it */
typedef struct gibake_shard_info {
  gibake_ddgi_volume volume;   /* the complete bake's volume description */
  uint64_t input_hash;         /* the complete bake's input hash (equals the file header's) */
  uint64_t settings_hash;      /* XXH3-64 of the canonical settings JSON */
  uint32_t shard_index;        /* I, 0 <= I < N */
  uint32_t shard_count;        /* N */
  uint32_t probe_begin;        /* first probe of the shard */
  uint32_t probe_end;          /* one past its last probe */
  uint32_t flags;              /* GIBAKE_SHARD_FLAG_* */
  uint32_t sh_format;          /* storage the merged file uses: 0 auto, 1 f16, 2 f32 */
  uint32_t atlas_format;       /* the same for the atlases */
  uint32_t closed_inside;      /* closed-mesh check sums over the shard's probes */
  uint32_t closed_inside_but_active;
  uint32_t closed_inactive_outside;
  uint64_t bounce_hit_count;   /* elements / 10 of the bounce-hit section */
  uint32_t volume_index;       /* which of the bake's DDGI volumes (the file's order) */
  uint32_t volume_count;       /* the bake's DDGI volumes: one shard_info (and sections) each */
  uint32_t first_block;        /* the volume's first probe block among the bake's (512 probes each) */
  uint32_t total_blocks;       /* the bake's probe blocks, every volume's */
  uint32_t reserved[12];       /* 0 */
} gibake_shard_info;

/* One probe of a shard: what the merge needs besides its SH, texels and depth tile. */
#define GIBAKE_SHARD_PROBE_INACTIVE 1u /* the ray test's verdict (back faces or enclosed) */
#define GIBAKE_SHARD_PROBE_ENCLOSED 2u
#define GIBAKE_SHARD_PROBE_SKY_ONLY 4u
#define GIBAKE_SHARD_PROBE_MOVED 8u
typedef struct gibake_shard_probe {
  float offset[3];           /* relocation offset, metres */
  uint32_t flags;            /* GIBAKE_SHARD_PROBE_* */
  gibake_probe_stats stats;  /* as in ddgi_stats */
  uint32_t integrated_rays;  /* rays pass 0 integrated */
  uint32_t bounce_hits;      /* its hits in the bounce-hit section (in probe order) */
  uint64_t primary_rays, shadow_rays, bounce_rays, relocation_rays;
} gibake_shard_probe;

#ifdef __cplusplus
#define GIBAKE_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
#else
#define GIBAKE_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)
#endif

GIBAKE_STATIC_ASSERT(sizeof(gibake_file_header) == 64, "header is 64 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_file_header, version_major) == 8, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_file_header, header_size) == 12, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_file_header, section_table_offset) == 24, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_file_header, file_size) == 32, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_file_header, input_hash) == 40, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_file_header, header_checksum) == 48, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_file_header, table_checksum) == 56, "layout");
GIBAKE_STATIC_ASSERT(sizeof(gibake_section_entry) == 64, "table entry is 64 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_section_entry, offset) == 8, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_section_entry, size) == 16, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_section_entry, count) == 24, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_section_entry, checksum) == 32, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_section_entry, group) == 40, "layout");
GIBAKE_STATIC_ASSERT(sizeof(gibake_ddgi_volume) == 128, "volume is 128 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, counts) == 40, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, sh_order) == 56, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, irradiance_width) == 84, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, flags) == 100, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, atlas_planes_per_row) == 104, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, stored_probes) == 108, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, atlas_tiles_per_row) == 112, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume, irradiance_scale) == 124, "layout");
GIBAKE_STATIC_ASSERT(sizeof(gibake_probe_stats) == 16, "stats are 16 bytes");
GIBAKE_STATIC_ASSERT(sizeof(gibake_lpv_cascade) == 64, "lpv cascade is 64 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_lpv_cascade, cell_size) == 12, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_lpv_cascade, dims) == 16, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_lpv_cascade, cell_count) == 28, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_lpv_cascade, cascade_index) == 32, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_lpv_cascade, iterations) == 40, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_lpv_cascade, units) == 48, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_lpv_cascade, flags) == 52, "layout");
GIBAKE_STATIC_ASSERT(sizeof(gibake_shard_info) == 256, "shard info is 256 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_shard_info, input_hash) == 128, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_shard_info, bounce_hit_count) == 184, "layout");
GIBAKE_STATIC_ASSERT(sizeof(gibake_shard_probe) == 72, "shard probe is 72 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_shard_probe, primary_rays) == 40, "layout");

GIBAKE_STATIC_ASSERT(sizeof(gibake_ddgi_volume_index) == GIBAKE_DDGI_INDEX_HEADER_WORDS * 4, "index header is 64 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume_index, dims) == 16, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume_index, volume_count) == 32, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_ddgi_volume_index, longest) == 40, "layout");

GIBAKE_STATIC_ASSERT(sizeof(gibake_vxgi_volume) == 80, "vxgi volume is 80 bytes");
GIBAKE_STATIC_ASSERT(offsetof(gibake_vxgi_volume, diffuse_scale) == 64, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_vxgi_volume, dims) == 16, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_vxgi_volume, levels) == 28, "layout");
GIBAKE_STATIC_ASSERT(offsetof(gibake_vxgi_volume, sky) == 48, "layout");

/* Bytes per element of a format; 0 for unknown formats and for STRUCT (depends on the type). */
static inline uint32_t gibake_format_element_size(uint32_t format) {
  switch (format) {
    case GIBAKE_FORMAT_F32: return 4;
    case GIBAKE_FORMAT_F16: return 2;
    case GIBAKE_FORMAT_F32X3: return 12;
    case GIBAKE_FORMAT_U8: return 1;
    case GIBAKE_FORMAT_U32: return 4;
    case GIBAKE_FORMAT_RGBA16F: return 8;
    case GIBAKE_FORMAT_RGBA32F: return 16;
    case GIBAKE_FORMAT_RG16F: return 4;
    case GIBAKE_FORMAT_RG32F: return 8;
    case GIBAKE_FORMAT_PROBE_STATS: return 16;
    case GIBAKE_FORMAT_JSON: return 1;
    case GIBAKE_FORMAT_RGB9E5:
      return 4;
    default: return 0;
  }
}

#endif /* GIBAKE_FORMAT_H */
