// libFuzzer input as a file: the importer and the sky reader open paths, so each input is written
// to one scratch file per process (in /dev/shm when it exists: no disk traffic per run).
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace gibake::fuzz {

inline std::string scratch_path(const std::string& name) {
  const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
  return dir + "/gibake_fuzz_" + std::to_string(getpid()) + "_" + name;
}

inline bool write_input(const std::string& path, const uint8_t* data, size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const bool ok = std::fwrite(data, 1, size, f) == size;
  return std::fclose(f) == 0 && ok;
}

}  // namespace gibake::fuzz
