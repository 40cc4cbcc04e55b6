#include "io/output/depfile.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace gibake {

std::string depfile_escape(const std::string& path) {
  std::string out;
  out.reserve(path.size());
  size_t backslashes = 0;  // the run of backslashes just before this character
  for (char c : path) {
    if (c == ' ' || c == '#') {
      // Make and Ninja read 2N backslashes before an escaped space or '#' as N: the run is doubled
      // there, and only there (elsewhere a backslash is read as itself).
      out.append(backslashes, '\\');
      out += '\\';
    }
    if (c == '$') out += '$';
    out += c;
    backslashes = c == '\\' ? backslashes + 1 : 0;
  }
  return out;
}

char depfile_unwritable(const std::string& path) {
  for (char c : path)
    if (c == '\n' || c == '\r' || c == '\t' || c == ':' || c == ';' || c == '%' || c == '=') return c;
  return 0;
}

std::string depfile_char_name(char c) {
  switch (c) {
    case '\n':
      return "a newline";
    case '\r':
      return "a carriage return";
    case '\t':
      return "a tab";
    default:
      return std::string("'") + c + "'";
  }
}

std::string depfile_input_path(const std::string& path) {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::absolute(path, ec);
  return ec ? path : p.lexically_normal().string();
}

Status write_depfile(const std::string& depfile_path, const std::string& target,
                     const std::vector<std::string>& inputs) {
  std::vector<std::string> paths{target};
  for (const std::string& input : inputs) {
    std::string p = depfile_input_path(input);
    if (std::find(paths.begin() + 1, paths.end(), p) == paths.end()) paths.push_back(std::move(p));
  }
  for (const std::string& p : paths)
    if (const char c = depfile_unwritable(p))
      return Status::error(ExitCode::BadArguments, depfile_path, "--depfile",
                           "'" + p + "' holds " + depfile_char_name(c) + ", which a Makefile rule cannot hold");
  std::string text = depfile_escape(target) + ":";
  for (size_t i = 1; i < paths.size(); ++i) text += " \\\n  " + depfile_escape(paths[i]);
  text += "\n";
  for (size_t i = 1; i < paths.size(); ++i) text += "\n" + depfile_escape(paths[i]) + ":\n";

  const std::string tmp = depfile_path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return Status::io(depfile_path, std::string("cannot create: ") + std::strerror(errno));
    out << text;
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      return Status::io(depfile_path, "write failed");
    }
  }
  if (std::rename(tmp.c_str(), depfile_path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    return Status::io(depfile_path, std::string("cannot rename: ") + std::strerror(err));
  }
  return Status::ok();
}

}  // namespace gibake
