// Ray -> probe integration: incident-radiance SH, cosine-weighted irradiance texels and
// depth moments (mean, mean^2) with DDGI's pow(max(0, dot), 64) weight.
// All estimates are Monte-Carlo over uniformly distributed directions: (4pi/N) sum f(w).
#pragma once
#include <cstdint>
#include <vector>

#include "kernels/vec.h"

namespace gibake::kernels {

// One traced ray as the integrator sees it (2 x vec4).
struct RaySample {
  float dir_depth[4];  // unit direction, depth recorded for visibility (m)
  float radiance[4];   // incident radiance along -dir at the probe (cd/m^2), w unused
};

// Texel directions of a res x res octahedral tile (xyz per texel, row-major).
std::vector<float> oct_tile_directions(int res);

// For the depth filter: the octahedral square is cut into bucket_res^2 buckets; for each bucket,
// the texels whose direction is within the cone where pow(dot,64) exceeds `min_weight`, widened
// by the largest angular radius of a bucket, so a ray falling into a bucket only visits those
// candidates (about 16 of 256 texels with 64x64 buckets, instead of all 256).
struct DepthConeTable {
  int res = 0;
  int bucket_res = 0;
  float cos_cutoff = 1.f;          // dot below which the weight is treated as zero
  std::vector<float> directions;   // res*res*3
  std::vector<uint32_t> offsets;   // bucket_res^2+1 into candidates
  std::vector<uint16_t> candidates;
  std::vector<float> dir_x, dir_y, dir_z;  // `directions` as structure-of-arrays
};
DepthConeTable build_depth_cone_table(int res, float min_weight = 0.02f, int bucket_res = 64);

// SH (RGB-interleaved, sh_coefficient_count(order)*3) and irradiance texels (res*res*3, lux;
// skipped when irradiance_out is null, e.g. for intermediate bounces that only need the SH).
// `norm_count` > 0: the norm is 4pi/norm_count instead of 4pi/n, for the probe rays followed by
// their paired emitter samples (bake/trace/path_gather.h), whose radiance is pre-scaled for it.
void integrate_radiance(const float* texel_dirs, int res, const RaySample* rays, int n, int sh_order,
                        float* sh_out, float* irradiance_out, int norm_count = 0);

// Depth moments per texel (res*res*2). Texels no ray reached take the closest ray's depth.
void integrate_depth(const DepthConeTable& table, const RaySample* rays, int n, float* depth_out);

}  // namespace gibake::kernels
