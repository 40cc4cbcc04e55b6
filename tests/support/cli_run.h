// Running the gibake executable from tests: exit code, stdout and stderr kept apart.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace gibake::test {

struct CliResult {
  int exit_code = -1;  // -1 when the process did not exit normally (e.g. a crash)
  std::string out, err;
};

// Single-quotes `s` for /bin/sh.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs `gibake <args>` (args already quoted as needed) with no stdin.
inline CliResult run_gibake_cli(const std::string& args) {
  static int counter = 0;
  const std::string base = std::string(P_tmpdir) + "/gibake_cli_" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++);
  const std::string out = base + ".out", err = base + ".err";
  const std::string cmd = shell_quote(GIBAKE_EXE) + " " + args + " >" + shell_quote(out) + " 2>" +
                          shell_quote(err) + " </dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  if (status != -1 && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  r.out = read_text_file(out);
  r.err = read_text_file(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return r;
}

inline std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> v;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) v.push_back(line);
  return v;
}

// The MiB of the first "memory: about N MiB of host memory estimated" note, -1 without one.
inline long noted_memory_mib(const CliResult& r) {
  const std::string note = "memory: about ";
  const size_t at = r.err.find(note);
  return at == std::string::npos ? -1L : std::stol(r.err.substr(at + note.size()));
}

}  // namespace gibake::test
