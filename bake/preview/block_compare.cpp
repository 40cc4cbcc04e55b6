// The image measure of the picture checks (block_compare.h).
#include "bake/preview/block_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
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

Status block_ratios(const PreviewImage& test, const PreviewImage& ref, int block, float floor_fraction,
                    BlockRatios& out) {
  out = BlockRatios{};
  if (test.width != ref.width || test.height != ref.height)
    return Status::error(ExitCode::BadArguments, "", "--diff", "the images differ in size");
  if (block < 1) return Status::error(ExitCode::BadArguments, "", "--diff", "block size must be positive");
  const std::vector<double> sum_test = block_sums(test.rgb, test.width, test.height, block);
  const std::vector<double> sum_ref = block_sums(ref.rgb, ref.width, ref.height, block);
  out.block = block;
  out.columns = ref.width / block;
  out.rows = ref.height / block;
  out.counted = counted_blocks(sum_ref, floor_fraction);
  out.ratio.assign(sum_ref.size(), std::numeric_limits<double>::quiet_NaN());
  for (size_t b = 0; b < sum_ref.size(); ++b)
    if (out.counted[b]) out.ratio[b] = sum_test[b] / sum_ref[b];
  return Status::ok();
}

BlockComparison block_comparison(const BlockRatios& r, float within) {
  std::vector<double> ratios;
  for (size_t b = 0; b < r.ratio.size(); ++b)
    if (r.counted[b]) ratios.push_back(r.ratio[b]);
  BlockComparison out;
  out.blocks = ratios.size();
  out.ratio = ratio_stats(ratios, within);
  return out;
}

Status compare_blocks(const PreviewImage& test, const PreviewImage& ref, int block, float within, float floor_fraction,
                      BlockComparison& out) {
  out = BlockComparison{};
  BlockRatios r;
  GIBAKE_TRY(block_ratios(test, ref, block, floor_fraction, r));
  out = block_comparison(r, within);
  return Status::ok();
}

std::vector<BlockAt> worst_blocks(const BlockRatios& r, float within, size_t count) {
  std::vector<std::pair<double, size_t>> far;  // |log ratio|, block index
  for (size_t b = 0; b < r.ratio.size(); ++b) {
    const double v = r.ratio[b];
    if (!r.counted[b] || std::fabs(v - 1.0) <= within) continue;  // NaN is not within
    const double off = v > 0.0 && std::isfinite(v) ? std::fabs(std::log(v)) : std::numeric_limits<double>::infinity();
    far.push_back({off, b});
  }
  std::stable_sort(far.begin(), far.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<BlockAt> out;
  for (size_t k = 0; k < std::min(count, far.size()); ++k) {
    const size_t b = far[k].second;
    const int column = int(b % size_t(r.columns)), row = int(b / size_t(r.columns));
    out.push_back({column * r.block + r.block / 2, row * r.block + r.block / 2, r.ratio[b]});
  }
  return out;
}

std::vector<uint8_t> block_map_rgb8(const PreviewImage& ref, const BlockRatios& r, float within) {
  const std::vector<uint8_t> shown = tonemap_rgb8(ref, Tonemap{});
  std::vector<uint8_t> out(shown.size());
  constexpr float kRed[3] = {230.f, 30.f, 30.f}, kBlue[3] = {30.f, 80.f, 230.f};
  constexpr float kDimmed = 0.35f;  // blocks the comparison leaves out
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      const size_t i = (size_t(y) * ref.width + x) * 3;
      const float grey = 0.2126f * shown[i] + 0.7152f * shown[i + 1] + 0.0722f * shown[i + 2];
      const int column = r.block > 0 ? x / r.block : 0, row = r.block > 0 ? y / r.block : 0;
      const bool whole = column < r.columns && row < r.rows;
      const size_t b = whole ? size_t(row) * r.columns + column : 0;
      const double v = whole ? r.ratio[b] : 1.0;
      float rgb[3] = {grey, grey, grey};
      if (!whole || !r.counted[b]) {
        for (float& c : rgb) c *= kDimmed;
      } else if (!(std::fabs(v - 1.0) <= within)) {  // NaN too
        // A tint from 0.4 just past `within` to 0.9 at twice or half (|log2 ratio| = 1).
        const float far = v > 0.0 && std::isfinite(v) ? float(std::min(1.0, std::fabs(std::log2(v)))) : 1.f;
        const float alpha = 0.4f + 0.5f * far;
        const float* tint = v < 1.0 ? kBlue : kRed;  // NaN: red
        for (int k = 0; k < 3; ++k) rgb[k] = grey * (1.f - alpha) + tint[k] * alpha;
      }
      for (int k = 0; k < 3; ++k) out[i + size_t(k)] = uint8_t(std::lround(std::clamp(rgb[k], 0.f, 255.f)));
    }
  return out;
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
