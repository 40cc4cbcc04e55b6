// The image measure of the picture checks: a lit preview against its reference, block by block,
// and the reference's own noise from its two halves.
#pragma once
#include <cstddef>

#include "bake/preview/preview.h"
#include "bake/preview/reconstruction_check.h"
#include "io/status.h"

namespace gibake {

// 8x8-pixel block comparison of a lit preview against its reference (the image measure of
// default-bake checks): luminance summed per block, blocks whose reference is below floor_fraction
// x the mean block left out; ratio = test / reference per block.
struct BlockComparison {
  size_t blocks = 0;  // counted
  RatioDistribution ratio;
};
Status compare_blocks(const PreviewImage& test, const PreviewImage& reference, int block, float within,
                      float floor_fraction, BlockComparison& out);

// The reference's own error per block, from its two halves: with h of its n samples in the first
// half (mean A) and the rest in the second (mean B), A - B has sqrt(n^2 / (h (n - h))) times the
// spread of the full mean's error, so e = |A - B| sqrt(h (n - h)) / n / full is distributed as the
// full reference's relative error on that block (exactly so for Gaussian noise). `within` is then
// the share of blocks on which the reference itself is about that close to the truth: the most a
// perfect bake compared with it can score. Blocks as compare_blocks counts them.
struct ReferenceNoise {
  size_t blocks = 0;
  double within = 0.0;        // share of blocks with e <= the given fraction
  double median_error = 0.0;  // median e
};
Status reference_noise(const PreviewImage& reference, int block, float within, float floor_fraction,
                       ReferenceNoise& out);

}  // namespace gibake
