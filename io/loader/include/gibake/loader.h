/* C API of the gibake runtime loader (C11; format.h uses _Static_assert). A thin wrapper over gibake/loader.hpp: open and
 * validate a bake file, read the DDGI volume description, sample irradiance.
 * Return codes are gibake loader error codes: 0 success, otherwise the ErrorCode value
 * (see gibake_error_name). No function reads outside the buffers it was given.
 * Units as in gibake/loader.hpp: metres, world space (+Y up), irradiance in lux, radiance in cd/m^2;
 * normals are unit vectors. Pointers returned for a file are valid until gibake_close. After a
 * successful open, any number of threads may read and sample the same file at once.
 *
 * Example:
 *   gibake_file* f = NULL;
 *   char msg[256];
 *   if (gibake_open_path("scene.gibake", 1, &f, msg, sizeof msg) != 0) { fprintf(stderr, "%s\n", msg); return; }
 *   const float p[3] = {1.f, 0.5f, -2.f}, n[3] = {0.f, 1.f, 0.f};
 *   float e[3];  int inside = 0;
 *   gibake_sample_ddgi(f, p, n, e, &inside);  (e: lux; inside 0 when p is outside every volume)
 *   gibake_close(f); */
#ifndef GIBAKE_LOADER_H
#define GIBAKE_LOADER_H

#include <stddef.h>
#include <stdint.h>

#include "gibake/format.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct gibake_file gibake_file; /* opaque */

/* Opens a file by path (read into memory) or copies a memory block. `error` (optional) receives a
 * NUL-terminated message of at most error_size bytes. *out is NULL on failure. */
int gibake_open_path(const char* path, int verify_checksums, gibake_file** out, char* error, size_t error_size);
int gibake_open_memory(const void* data, size_t size, int verify_checksums, gibake_file** out, char* error,
                       size_t error_size);
void gibake_close(gibake_file* file);
const char* gibake_error_name(int code);

const gibake_file_header* gibake_header(const gibake_file* file);
uint32_t gibake_ddgi_volume_count(const gibake_file* file);
/* NULL when volume is out of range. */
const gibake_ddgi_volume* gibake_ddgi_volume_desc(const gibake_file* file, uint32_t volume);
/* Metadata JSON bytes (not NUL-terminated) and their size; NULL/0 when absent. */
const char* gibake_metadata(const gibake_file* file, size_t* size);

/* sh_coefficients*3 floats of one probe (converted from f16 when stored so). */
int gibake_probe_sh(const gibake_file* file, uint32_t volume, uint32_t probe, float* out);
/* World position (rest + offset) and state of a probe. */
int gibake_probe_position(const gibake_file* file, uint32_t volume, uint32_t probe, float out_xyz[3]);
uint32_t gibake_probe_state_of(const gibake_file* file, uint32_t volume, uint32_t probe);
/* The sampling calls below return non-zero (and leave out_rgb as it was) for a p or n that is not
 * three finite numbers. */
/* Irradiance (lux) at world point p with unit normal n, default SampleOptions. */
int gibake_sample_irradiance(const gibake_file* file, uint32_t volume, const float p[3], const float n[3],
                             float out_rgb[3]);
/* Irradiance (lux) at p blended over every DDGI volume (BakeFile::sample_ddgi, docs/FORMAT.md
 * "Several volumes"). *inside (optional) is 1 when p lies in some volume's region, else 0 (out_rgb
 * then holds the nearest volume's clamped answer). */
int gibake_sample_ddgi(const gibake_file* file, const float p[3], const float n[3], float out_rgb[3], int* inside);

/* (1.2) Light propagation volume cascades, ordered by cascade_index (0 = finest). */
uint32_t gibake_lpv_cascade_count(const gibake_file* file);
/* NULL when cascade is out of range. */
const gibake_lpv_cascade* gibake_lpv_cascade_desc(const gibake_file* file, uint32_t cascade);
/* 12 floats of one cell: [R,G,B][4 SH coefficients] of radiant intensity, cd. */
int gibake_lpv_cell_sh(const gibake_file* file, uint32_t cascade, uint32_t cell, float out[12]);
/* LPV irradiance (lux) at p for unit normal n from the finest cascade containing p (0 outside). */
int gibake_sample_lpv(const gibake_file* file, const float p[3], const float n[3], float out_rgb[3]);

#ifdef __cplusplus
}
#endif

#endif /* GIBAKE_LOADER_H */
