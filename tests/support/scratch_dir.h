// Scratch space for tests. Every test process gets its own fresh folder, made with mkdtemp
// under the system's temporary folder and removed, with all it holds, when the process ends.
// A name built from the pid alone is not enough: pids are reused within one ctest run on a
// busy machine, and a folder a crashed or earlier process left behind would then hold files
// a test expects not to exist.
#pragma once
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace gibake::test {

namespace detail {
struct ProcessTmp {
  std::filesystem::path dir;
  ProcessTmp() {
    const std::string pattern =
        (std::filesystem::temp_directory_path() / ("gibake_test_" + std::to_string(::getpid()) + "_XXXXXX")).string();
    std::vector<char> buffer(pattern.begin(), pattern.end());
    buffer.push_back('\0');
    if (!::mkdtemp(buffer.data())) throw std::runtime_error("mkdtemp failed for " + pattern);
    dir = buffer.data();
  }
  ~ProcessTmp() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};
}  // namespace detail

// This process's own fresh temporary folder.
inline const std::filesystem::path& process_tmp() {
  static const detail::ProcessTmp tmp;
  return tmp.dir;
}

// A scratch folder for one test inside process_tmp(): made empty when the object is, removed
// with all it holds when it goes.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name) : dir_(process_tmp() / name) {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
    std::filesystem::create_directories(dir_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& dir() const { return dir_; }
  std::string path(const std::string& file) const { return (dir_ / file).string(); }

 private:
  std::filesystem::path dir_;
};

}  // namespace gibake::test
