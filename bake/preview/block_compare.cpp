// The image measure of the picture checks (block_compare.h).
#include "bake/preview/block_compare.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "kernels/vec.h"

namespace gibake {

namespace {

// Luminance summed over each whole block x block tile of an RGB image, row by row (the partial
// tiles at the right and bottom edges left out).
std::vector<double> block_sums(const std::vector<float>& rgb, int width, int height, int block) {
  const int bx = width / block, by = height / block;
  std::vector<double> sums(size_t(bx) * by, 0.0);
  for (int y = 0; y < by * block; ++y)
    for (int x = 0; x < bx * block; ++x) {
      const size_t i = (size_t(y) * width + x) * 3;
      sums[size_t(y / block) * bx + x / block] += kernels::luminance(&rgb[i]);
    }
  return sums;
}

// The blocks a comparison counts: a reference above floor_fraction x the mean block (black
// against black says nothing).
std::vector<bool> counted_blocks(const std::vector<double>& reference, float floor_fraction) {
  double mean = 0.0;
  for (double v : reference) mean += v;
  mean = reference.empty() ? 0.0 : mean / double(reference.size());
  std::vector<bool> counted(reference.size());
  for (size_t b = 0; b < reference.size(); ++b) counted[b] = reference[b] > floor_fraction * mean && reference[b] > 0.0;
  return counted;
}

}  // namespace

Status compare_blocks(const PreviewImage& test, const PreviewImage& ref, int block, float within, float floor_fraction,
                      BlockComparison& out) {
  out = BlockComparison{};
  if (test.width != ref.width || test.height != ref.height)
    return Status::error(ExitCode::BadArguments, "", "--diff", "the images differ in size");
  if (block < 1) return Status::error(ExitCode::BadArguments, "", "--diff", "block size must be positive");
  const std::vector<double> sum_test = block_sums(test.rgb, test.width, test.height, block);
  const std::vector<double> sum_ref = block_sums(ref.rgb, ref.width, ref.height, block);
  const std::vector<bool> counted = counted_blocks(sum_ref, floor_fraction);
  std::vector<double> ratios;
  for (size_t b = 0; b < sum_ref.size(); ++b)
    if (counted[b]) ratios.push_back(sum_test[b] / sum_ref[b]);
  out.blocks = ratios.size();
  out.ratio = ratio_stats(ratios, within);
  return Status::ok();
}

Status reference_noise(const PreviewImage& ref, int block, float within, float floor_fraction, ReferenceNoise& out) {
  out = ReferenceNoise{};
  const int h = ref.spp / 2;
  if (h < 1 || ref.first_half_rgb.size() != ref.rgb.size())
    return Status::error(ExitCode::BadArguments, "", "--spp", "the reference's noise needs at least 2 samples a pixel");
  if (block < 1) return Status::error(ExitCode::BadArguments, "", "--diff", "block size must be positive");
  const std::vector<double> full = block_sums(ref.rgb, ref.width, ref.height, block);
  const std::vector<double> first = block_sums(ref.first_half_rgb, ref.width, ref.height, block);
  const std::vector<bool> counted = counted_blocks(full, floor_fraction);
  const double n = ref.spp, scale = std::sqrt(double(h) * (n - h)) / n;
  std::vector<double> errors;
  size_t close = 0;
  for (size_t b = 0; b < full.size(); ++b) {
    if (!counted[b]) continue;
    const double second = (n * full[b] - h * first[b]) / (n - h);
    errors.push_back(std::abs(first[b] - second) * scale / full[b]);
    close += errors.back() <= within;
  }
  out.blocks = errors.size();
  if (errors.empty()) return Status::ok();
  out.within = double(close) / double(errors.size());
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  out.median_error = errors[errors.size() / 2];
  return Status::ok();
}

}  // namespace gibake
