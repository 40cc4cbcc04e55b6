// A bake file begun while the DDGI bake still traces, so that its two atlases (nearly all of
// the file) are encoded and written as their rows become final rather than after
// the trace. Rows become final in any order (a band of tile rows once its probes finished: the
// trace's chunks are slabs along z, and each z holds one tile row in every band of Y planes); the
// section checksums follow the rows written in order, and finish() hashes what is left. The file's layout depends only
// on the sections' sizes and formats, which the first volume's shape gives before its values exist; the writer
// (write_bake_file, through BakeFileOptions::stream) adopts what was streamed when the finished outputs lay out exactly
// as predicted, and otherwise writes the file from scratch. Either way the bytes are the same.
#pragma once
#include <tbb/task_arena.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "gibake/format.h"
#include "io/bakefile/bake_file.h"
#include "io/output/bake_atomic.h"

struct XXH64_state_s;

namespace gibake {

// What the layout of the first DDGI volume's sections depends on (every per-probe section present:
// a whole bake's volume).
struct DdgiFileShape {
  uint64_t probes = 0;
  uint64_t sh_values = 0;                           // probes x coefficients x RGB
  int irradiance_width = 0, irradiance_height = 0;  // texels, RGBA
  int depth_width = 0, depth_height = 0;            // texels, mean and mean^2
};

// The section table write_bake_file lays out for a file whose first section group is one DDGI volume
// of this shape, up to that volume's last section (the depth atlas), the atlases stored as float16
// (`atlas_half`) or float32, and where the next section would start (`end`, aligned as the writer
// aligns sections). False when the SH's format depends on their values (options.sh Auto).
bool predict_ddgi_table(const DdgiFileShape& shape, const BakeFileOptions& options, bool atlas_half,
                        std::vector<gibake_section_entry>& table, uint64_t& end);

class BakeFileStream {
 public:
  enum Atlas { kIrradiance = 0, kDepth = 1 };

  // The file write_bake_file will write: its path, the inputs it must not overwrite, its options.
  BakeFileStream(std::string path, std::vector<std::string> inputs, const BakeFileOptions& options);
  ~BakeFileStream();  // stops the encoding; the temporary goes unless the writer committed it
  BakeFileStream(const BakeFileStream&) = delete;
  BakeFileStream& operator=(const BakeFileStream&) = delete;

  // Opens the temporary and starts encoding rows as they become final. `irradiance` and `depth` are
  // the atlases' values (the result's buffers: neither moved nor resized until the write). The
  // atlases are guessed float16 unless options.atlas is Full; a value beyond float16 under Auto
  // proves the guess wrong and the stream stops (the writer then writes the file whole). Nothing streams
  // when the layout cannot be predicted or the temporary cannot be opened (the writer reports that).
  void open(const DdgiFileShape& shape, const float* irradiance, const float* depth);
  bool active() const { return opened_ && !failed_.load(); }
  // Texel rows [first, last) of `atlas` hold their final values. Any thread, any order; rows told
  // twice are written once.
  void rows_final(Atlas atlas, int first, int last);

  // For write_bake_file. Stops the encoding and encodes, writes and hashes the rows left (in
  // `arena`); true when it did, the atlases being still `irradiance` and `depth` of these sizes.
  // False too when less than half of the atlases' bytes had streamed: the writer's own path is then
  // as fast. `clamped` gets the values clamped to 65504 (options.atlas Half).
  bool finish(const std::vector<float>& irradiance, const std::vector<float>& depth, tbb::task_arena& arena,
              size_t& clamped);
  bool atlas_half() const { return half_; }
  // Texel rows of `atlas` written so far; after finish(), those written before it (what the stream
  // hid behind the bake). Of `rows(atlas)`.
  int rows_written(Atlas atlas);
  int rows(Atlas atlas) const { return atlases_[atlas].rows; }
  // Finished, and its file kept for the writer (not abandoned).
  bool adopted() const { return atlases_[kIrradiance].written_early >= 0 && !abandoned_; }
  // Whether `table` (the writer's, for the finished outputs) places the two atlases as predicted.
  bool matches(const std::vector<gibake_section_entry>& table) const;
  // The two atlases' checksums (valid after finish).
  uint64_t checksum(Atlas atlas) const { return atlases_[atlas].checksum; }
  // The file's buffer, the atlases and their padding in place, grown to `size` bytes (malloc'd: the
  // caller frees it with free()).
  uint8_t* take_buffer(size_t size);
  AtomicFile& file() { return file_; }
  // Removes the temporary now (the writer writes a file of its own).
  void abandon();

 private:
  // A texel row's way through the stream (under mutex_).
  enum RowState : uint8_t { kPending = 0, kFinal, kTaken, kWritten };
  struct StreamedAtlas {
    const float* values = nullptr;
    uint64_t row_values = 0;  // floats per texel row
    int rows = 0;
    uint64_t offset = 0, end = 0;  // in the file: the section, then its padding up to `end`
    std::vector<RowState> state;   // per texel row
    int hashed = 0;                // rows [0, hashed) in the checksum (the worker's until stopped)
    int written_early = -1;        // rows written before finish() (-1: not finished)
    uint64_t checksum = 0;
    std::unique_ptr<XXH64_state_s, void (*)(XXH64_state_s*)> hash{nullptr, nullptr};
    uint64_t row_bytes(bool half) const { return row_values * (half ? 2 : 4); }
  };
  void run();
  // The first run of final rows of `a` (at most `most`), marked taken; false when there is none.
  bool take_final_rows(StreamedAtlas& a, int most, int& first, int& last);
  // Encodes rows [first, last) of `a` into the buffer; false when Auto's float16 guess fails.
  bool encode_rows(const StreamedAtlas& a, int first, int last, size_t& clamped);
  // Adds the written rows after a.hashed to its checksum, in order.
  void hash_written_rows(StreamedAtlas& a);
  bool write_range(uint64_t offset, const uint8_t* data, size_t size);
  void stop();

  std::string path_;
  std::vector<std::string> inputs_;
  BakeFileOptions options_;
  AtomicFile file_;
  std::vector<gibake_section_entry> predicted_;
  StreamedAtlas atlases_[2];
  bool half_ = true;
  uint8_t* buffer_ = nullptr;  // malloc'd, up to the depth section's padded end
  size_t buffer_size_ = 0;
  size_t clamped_ = 0;
  bool opened_ = false, abandoned_ = false;
  std::atomic<bool> failed_{false};  // a guess proved wrong or a write failed: nothing more streams
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  int pending_rows_ = 0;  // final, not yet taken (under mutex_)
  std::thread worker_;
};

}  // namespace gibake
