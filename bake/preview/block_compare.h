// The image measure of the picture checks: a lit preview against its reference, block by block,
// and the reference's own noise from its two halves.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

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

// Every whole block's ratio test / reference, row by row (`columns` x `rows`; the partial blocks at
// the right and bottom edges left out), and whether compare_blocks counts it (NaN where not). A
// counted block whose test is not a number keeps its NaN: it is as wrong as a block can be.
struct BlockRatios {
  int block = 0, columns = 0, rows = 0;
  std::vector<double> ratio;
  std::vector<bool> counted;
};
Status block_ratios(const PreviewImage& test, const PreviewImage& reference, int block, float floor_fraction,
                    BlockRatios& out);
// compare_blocks' figures from ratios already taken.
BlockComparison block_comparison(const BlockRatios& ratios, float within);

// A block by the pixel at its centre (the X,Y that `preview --explain` takes) and its ratio.
struct BlockAt {
  int x = 0, y = 0;
  double ratio = 1.0;
};
// The counted blocks farther than `within` from 1, farthest first (by |log ratio|: twice and half
// equally far; black and not-a-number farthest; ties in row order), at most `count` of them.
std::vector<BlockAt> worst_blocks(const BlockRatios& ratios, float within, size_t count);

// Where the blocks fail, as an RGB8 image the size of `reference`: the reference in grey, each
// counted block farther than `within` from 1 tinted red (the lit view brighter, or not a number) or
// blue (darker), the more so the farther, fully at twice or half; blocks not counted dimmed.
std::vector<uint8_t> block_map_rgb8(const PreviewImage& reference, const BlockRatios& ratios, float within);

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
