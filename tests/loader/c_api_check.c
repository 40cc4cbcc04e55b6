/* Compiled as C11: format.h and loader.h are valid C; the C API opens, samples and rejects. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gibake/format.h"
#include "gibake/loader.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  char error[256];
  gibake_file* file = NULL;
  int rc = gibake_open_path(argv[1], 1, &file, error, sizeof error);
  if (rc != 0 || !file) {
    fprintf(stderr, "open failed: %s (%s)\n", gibake_error_name(rc), error);
    return 1;
  }
  if (gibake_ddgi_volume_count(file) != 1) return 1;
  const gibake_ddgi_volume* d = gibake_ddgi_volume_desc(file, 0);
  if (!d || d->probe_count != (uint32_t)(d->counts[0] * d->counts[1] * d->counts[2])) return 1;
  float sh[27], pos[3], rgb[3];
  const float n[3] = {0.f, 1.f, 0.f};
  if (gibake_probe_sh(file, 0, 0, sh) != 0 || gibake_probe_position(file, 0, 0, pos) != 0) return 1;
  if (gibake_sample_irradiance(file, 0, pos, n, rgb) != 0 || !(rgb[0] >= 0.f)) return 1;
  if (gibake_probe_sh(file, 0, d->probe_count, sh) == 0) return 1; /* out of range probe refused */
  /* One volume: the blend is that volume's sampler, to the bit, inside its region and outside. */
  float blended[3];
  int inside = -1;
  if (gibake_sample_ddgi(file, pos, n, blended, &inside) != 0 || inside != 1) return 1;
  if (memcmp(blended, rgb, sizeof rgb) != 0) return 1;
  const float far[3] = {1e4f, 1e4f, 1e4f};
  float clamped[3];
  if (gibake_sample_ddgi(file, far, n, blended, &inside) != 0 || inside != 0) return 1;
  if (gibake_sample_irradiance(file, 0, far, n, clamped) != 0 || memcmp(blended, clamped, sizeof clamped) != 0) return 1;
  if (gibake_sample_ddgi(file, NULL, n, blended, &inside) == 0) return 1;
  /* A point or normal that is not finite has no answer: refused, as a null one is. */
  const float nan_point[3] = {pos[0], NAN, pos[2]}, inf_normal[3] = {0.f, INFINITY, 0.f};
  if (gibake_sample_ddgi(file, nan_point, n, blended, &inside) == 0) return 1;
  if (gibake_sample_irradiance(file, 0, pos, inf_normal, clamped) == 0) return 1;
  if (gibake_sample_lpv(file, nan_point, n, clamped) == 0) return 1;
  size_t size = 0;
  const char* meta = gibake_metadata(file, &size);
  if (!meta || size == 0 || meta[0] != '{') return 1;
  printf("ok: %u probes, E = %g %g %g lux\n", d->probe_count, rgb[0], rgb[1], rgb[2]);
  gibake_close(file);
  const char garbage[100] = "GIBAKE";
  if (gibake_open_memory(garbage, sizeof garbage, 1, &file, error, sizeof error) == 0 || file) return 1;
  return 0;
}
