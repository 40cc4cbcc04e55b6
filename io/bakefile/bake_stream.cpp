// The bake file streamed during the trace (bake_stream.h): a worker thread encodes and writes each
// atlas's final rows as they come, and hashes the written rows in order; finish() does the rows left
// side by side.
#include "io/bakefile/bake_stream.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <xxhash.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "io/bakefile/half_encode.h"

namespace gibake {

namespace {

// finish() encodes and writes the rows left in pieces of about this many bytes, side by side.
constexpr uint64_t kFinishPiece = uint64_t(4) << 20;
// The worker's step: small, so that finish() waits for little.
constexpr uint64_t kStreamStep = uint64_t(1) << 20;
// Below this share of the atlases' bytes streamed, finish() gives the file back to the writer,
// whose own path (every section side by side, each hashed beside its write) is then as fast: a bake
// whose probes all finish at the end (adaptive rays on the device) has streamed next to nothing.
constexpr double kLeastStreamed = 0.5;

}  // namespace

BakeFileStream::BakeFileStream(std::string path, std::vector<std::string> inputs, const BakeFileOptions& options)
    : path_(std::move(path)), inputs_(std::move(inputs)), options_(options) {}

BakeFileStream::~BakeFileStream() {
  stop();
  std::free(buffer_);
}

void BakeFileStream::open(const DdgiFileShape& shape, const float* irradiance, const float* depth) {
  if (opened_ || !irradiance || !depth) return;
  half_ = options_.atlas != FloatPrecision::Full;
  uint64_t end = 0;
  if (!predict_ddgi_table(shape, options_, half_, predicted_, end) || predicted_.size() < 2) return;
  const size_t depth_at = predicted_.size() - 1, irr_at = depth_at - 1;
  if (predicted_[irr_at].type != GIBAKE_SECTION_DDGI_IRRADIANCE ||
      predicted_[depth_at].type != GIBAKE_SECTION_DDGI_DEPTH)
    return;
  buffer_size_ = size_t(end);
  buffer_ = static_cast<uint8_t*>(std::malloc(buffer_size_));  // pages touched only where encoded
  if (!buffer_ || !file_.begin(path_, inputs_)) return;        // the writer's own attempt reports it
  const int widths[2] = {shape.irradiance_width, shape.depth_width};
  const int heights[2] = {shape.irradiance_height, shape.depth_height};
  const uint64_t channels[2] = {4, 2};
  const float* values[2] = {irradiance, depth};
  for (int i = 0; i < 2; ++i) {
    StreamedAtlas& a = atlases_[i];
    const gibake_section_entry& e = predicted_[i == kIrradiance ? irr_at : depth_at];
    a.values = values[i];
    a.row_values = uint64_t(widths[i]) * channels[i];
    a.rows = heights[i];
    a.offset = e.offset;
    a.end = i == kIrradiance ? predicted_[depth_at].offset : buffer_size_;
    a.state.assign(size_t(heights[i]), kPending);
    a.hash = {XXH64_createState(), [](XXH64_state_s* s) { XXH64_freeState(s); }};
    XXH64_reset(a.hash.get(), GIBAKE_HASH_SEED);
  }
  opened_ = true;
  worker_ = std::thread([this] { run(); });
}

void BakeFileStream::rows_final(Atlas atlas, int first, int last) {
  if (!opened_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    StreamedAtlas& a = atlases_[atlas];
    for (int r = std::max(first, 0); r < std::min(last, a.rows); ++r)
      if (a.state[size_t(r)] == kPending) {
        a.state[size_t(r)] = kFinal;
        ++pending_rows_;
      }
  }
  wake_.notify_one();
}

bool BakeFileStream::take_final_rows(StreamedAtlas& a, int most, int& first, int& last) {
  first = 0;
  while (first < a.rows && a.state[size_t(first)] != kFinal) ++first;
  if (first == a.rows) return false;
  last = first;
  while (last < a.rows && last - first < most && a.state[size_t(last)] == kFinal) a.state[size_t(last++)] = kTaken;
  pending_rows_ -= last - first;
  return true;
}

void BakeFileStream::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || pending_rows_ > 0; });
    if (stopping_) return;
    for (StreamedAtlas& a : atlases_) {
      const int most = int(std::max<uint64_t>(1, kStreamStep / a.row_bytes(half_)));
      int first = 0, last = 0;
      if (!take_final_rows(a, most, first, last)) continue;
      lock.unlock();
      size_t clamped = 0;
      const uint64_t at = a.offset + uint64_t(first) * a.row_bytes(half_);
      const bool ok = encode_rows(a, first, last, clamped) &&
                      write_range(at, buffer_ + at, size_t(uint64_t(last - first) * a.row_bytes(half_)));
      lock.lock();
      if (!ok) {
        failed_ = true;
        return;
      }
      clamped_ += clamped;
      for (int r = first; r < last; ++r) a.state[size_t(r)] = kWritten;
      lock.unlock();
      hash_written_rows(a);
      lock.lock();
    }
  }
}

// Rows [first, last): encoded into the buffer at their place in the file.
bool BakeFileStream::encode_rows(const StreamedAtlas& a, int first, int last, size_t& clamped) {
  const uint64_t v0 = uint64_t(first) * a.row_values, n = uint64_t(last - first) * a.row_values;
  const float* src = a.values + v0;
  uint8_t* dst = buffer_ + a.offset + uint64_t(first) * a.row_bytes(half_);
  if (!half_) {
    std::memcpy(dst, src, size_t(n * 4));
    return true;
  }
  if (options_.atlas == FloatPrecision::Auto && any_beyond_half(src, size_t(n))) return false;  // float32 after all
  clamped += encode_half(src, size_t(n), dst);
  return true;
}

void BakeFileStream::hash_written_rows(StreamedAtlas& a) {
  int end = a.hashed;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    while (end < a.rows && a.state[size_t(end)] == kWritten) ++end;
  }
  if (end == a.hashed) return;
  const uint64_t bytes = a.row_bytes(half_);
  XXH64_update(a.hash.get(), buffer_ + a.offset + uint64_t(a.hashed) * bytes, size_t(uint64_t(end - a.hashed) * bytes));
  a.hashed = end;
}

bool BakeFileStream::write_range(uint64_t offset, const uint8_t* data, size_t size) {
  return bool(file_.write_at(offset, data, size));
}

void BakeFileStream::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (worker_.joinable()) worker_.join();
}

bool BakeFileStream::finish(const std::vector<float>& irradiance, const std::vector<float>& depth,
                            tbb::task_arena& arena, size_t& clamped) {
  if (!opened_) return false;
  stop();
  const std::vector<float>* given[2] = {&irradiance, &depth};
  for (int i = 0; i < 2; ++i)
    if (given[i]->data() != atlases_[i].values ||
        given[i]->size() != atlases_[i].row_values * uint64_t(atlases_[i].rows))
      failed_ = true;
  if (failed_) return false;
  uint64_t streamed = 0, total = 0;
  for (StreamedAtlas& a : atlases_) {
    a.written_early = int(std::count(a.state.begin(), a.state.end(), kWritten));
    streamed += uint64_t(a.written_early) * a.row_bytes(half_);
    total += uint64_t(a.rows) * a.row_bytes(half_);
  }
  if (double(streamed) < kLeastStreamed * double(total)) return false;
  std::atomic<bool> ok{true};
  std::atomic<size_t> clamped_left{0};
  const auto finish_atlas = [&](StreamedAtlas& a) {
    // The rows not written yet, in pieces of about kFinishPiece bytes, encoded side by side (every
    // value depends on its input only); then the checksum (in order, on one thread) beside their
    // writes and the padding's.
    const uint64_t bytes = a.row_bytes(half_);
    const int most = int(std::max<uint64_t>(1, kFinishPiece / bytes));
    std::vector<std::pair<int, int>> pieces;
    for (int r = 0; r < a.rows;) {
      if (a.state[size_t(r)] == kWritten) {
        ++r;
        continue;
      }
      const int first = r;
      while (r < a.rows && r - first < most && a.state[size_t(r)] != kWritten) ++r;
      pieces.emplace_back(first, r);
    }
    tbb::parallel_for(size_t(0), pieces.size(), [&](size_t k) {
      size_t piece_clamped = 0;
      if (!encode_rows(a, pieces[k].first, pieces[k].second, piece_clamped)) ok = false;
      clamped_left += piece_clamped;
    });
    if (!ok) return;
    const uint64_t to = a.offset + uint64_t(a.rows) * bytes;
    std::memset(buffer_ + to, 0, size_t(a.end - to));
    for (auto& s : a.state) s = kWritten;
    tbb::parallel_invoke(
        [&] {
          hash_written_rows(a);
          a.checksum = XXH64_digest(a.hash.get());
        },
        [&] {
          tbb::parallel_for(size_t(0), pieces.size(), [&](size_t k) {
            const uint64_t at = a.offset + uint64_t(pieces[k].first) * bytes;
            if (!write_range(at, buffer_ + at, size_t(uint64_t(pieces[k].second - pieces[k].first) * bytes)))
              ok = false;
          });
          if (a.end > to && !write_range(to, buffer_ + to, size_t(a.end - to))) ok = false;
        });
  };
  arena.execute([&] {
    tbb::parallel_invoke([&] { finish_atlas(atlases_[kIrradiance]); }, [&] { finish_atlas(atlases_[kDepth]); });
  });
  if (!ok) {
    failed_ = true;
    return false;
  }
  clamped = clamped_ + clamped_left;
  return true;
}

int BakeFileStream::rows_written(Atlas atlas) {
  std::lock_guard<std::mutex> lock(mutex_);
  const StreamedAtlas& a = atlases_[atlas];
  if (a.written_early >= 0) return a.written_early;
  return int(std::count(a.state.begin(), a.state.end(), kWritten));
}

bool BakeFileStream::matches(const std::vector<gibake_section_entry>& table) const {
  if (table.size() < predicted_.size()) return false;
  for (size_t i = 0; i < predicted_.size(); ++i) {
    const gibake_section_entry &p = predicted_[i], &t = table[i];
    if (p.type != t.type || p.format != t.format || p.offset != t.offset || p.size != t.size || p.count != t.count ||
        p.group != t.group)
      return false;
  }
  return true;
}

uint8_t* BakeFileStream::take_buffer(size_t size) {
  if (size > buffer_size_) {
    uint8_t* grown = static_cast<uint8_t*>(std::realloc(buffer_, size));  // large blocks: remapped, not copied
    if (!grown) return nullptr;
    buffer_ = grown;
    buffer_size_ = size;
  }
  uint8_t* out = buffer_;
  buffer_ = nullptr;
  buffer_size_ = 0;
  return out;
}

void BakeFileStream::abandon() {
  stop();
  abandoned_ = true;
  file_.abandon();
}

}  // namespace gibake
