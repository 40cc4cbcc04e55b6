// Helpers for the bake-file tests: scratch folders, files, running the gibake binary.
#pragma once
#include <sys/wait.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gibake/format.h"
#include "gibake/loader.hpp"
#include "tests/support/scratch_dir.h"

namespace gibake::test {

inline std::string scratch_dir(const std::string& name) {
  const auto dir = gibake::test::process_tmp() / ("loader_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

inline std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

struct RunResult {
  int exit_code = -1;
  std::string out;
};

// Runs `gibake <args>`, capturing stdout and stderr.
inline RunResult run_gibake(const std::string& args, bool merge_stderr = true) {
  RunResult r;
  const std::string cmd = std::string(GIBAKE_EXE) + " " + args + (merge_stderr ? " 2>&1" : " 2>/dev/null");
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Runs `gibake <args>` keeping only stdout.
inline RunResult run_gibake_stdout(const std::string& args) { return run_gibake(args, false); }

// Recomputes the table and header checksums after a test edited the table or header.
inline void reseal(std::vector<uint8_t>& bytes) {
  gibake_file_header h;
  std::memcpy(&h, bytes.data(), sizeof h);
  const size_t table = size_t(h.section_count) * sizeof(gibake_section_entry);
  if (h.section_table_offset + table <= bytes.size())
    h.table_checksum = loader::xxh64(bytes.data() + h.section_table_offset, table, 0);
  h.header_checksum = 0;
  h.header_checksum = loader::xxh64(&h, sizeof h, 0);
  std::memcpy(bytes.data(), &h, sizeof h);
}

inline gibake_section_entry* table_entry(std::vector<uint8_t>& bytes, size_t i) {
  gibake_file_header h;
  std::memcpy(&h, bytes.data(), sizeof h);
  return reinterpret_cast<gibake_section_entry*>(bytes.data() + h.section_table_offset) + i;
}

}  // namespace gibake::test
