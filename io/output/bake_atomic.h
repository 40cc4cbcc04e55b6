// Atomic file replacement for every writer (bake file, EXR, VDB): the output is written to a
// temporary ".<name>.tmp.<pid>.XXXXXX" in the target folder, fsynced and renamed over the target, then
// the folder is fsynced. On any failure, or SIGINT/SIGTERM/SIGHUP, the temporary is removed and
// the previous target survives. (SIGKILL cannot be caught: the target still survives intact, but
// a stale temporary remains until the next write to that target removes it.)
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "io/status.h"

namespace gibake {

class AtomicFile {
 public:
  AtomicFile() = default;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();  // removes the temporary unless commit() succeeded

  // Checks the folder exists, that `path` is not one of `inputs` (device + inode), creates the
  // temporary. Writers either write() to it or let a library write to temp_path() by name.
  Status begin(const std::string& path, const std::vector<std::string>& inputs = {});
  Status write(const void* data, size_t size);
  // `size` bytes at `offset` (pwrite), from any thread, in any order; then asks the kernel to start
  // writing them back to the disk (sync_file_range), so that the disk works while the caller builds
  // the rest and commit()'s fsync has less left to wait for. On failure the caller abandons.
  Status write_at(uint64_t offset, const void* data, size_t size);
  // fsync, close, rename over the target, fsync the folder. `durable` false: close and rename only,
  // for files whose loss in a crash costs nothing and whose readers check them (the BVH cache).
  Status commit(bool durable = true);
  void abandon();  // remove the temporary now

  const std::string& temp_path() const { return temp_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_, temp_;
  int fd_ = -1;
  int slot_ = -1;  // signal-cleanup registry slot
};

// The outputs a run of several writes makes (export's EXR files, its folder and its VDB): until
// keep(), a fatal signal removes them as it removes the temporaries (files first, then a folder
// if it is then empty), so that an interrupted run leaves nothing it made, as a failed one does.
// Only paths that did not exist before belong here: a file that existed keeps its new bytes.
class ProvisionalOutputs {
 public:
  ProvisionalOutputs() = default;
  ProvisionalOutputs(const ProvisionalOutputs&) = delete;
  ProvisionalOutputs& operator=(const ProvisionalOutputs&) = delete;
  ~ProvisionalOutputs();  // keep()s: only a signal removes them
  void add_file(const std::string& path);
  void add_folder(const std::string& path);
  void keep();

 private:
  std::vector<int> slots_;
};

// Writes `size` bytes atomically to `path`.
Status write_file_atomic(const std::string& path, const void* data, size_t size,
                         const std::vector<std::string>& inputs = {});

// Whether two paths name the same existing file (st_dev and st_ino).
bool same_file(const std::string& a, const std::string& b);

}  // namespace gibake
