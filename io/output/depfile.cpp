#include "io/output/depfile.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace gibake {

std::string depfile_escape(const std::string& path) {
  std::string out;
  out.reserve(path.size());
  for (char c : path) {
    if (c == ' ' || c == '#' || c == '\\') out += '\\';
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

namespace {

std::string absolute_path(const std::string& path) {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::absolute(path, ec);
  return ec ? path : p.lexically_normal().string();
}

}  // namespace

Status write_depfile(const std::string& depfile_path, const std::string& target,
                     const std::vector<std::string>& inputs) {
  std::string text = depfile_escape(absolute_path(target)) + ":";
  for (const std::string& input : inputs) text += " \\\n  " + depfile_escape(absolute_path(input));
  text += "\n";

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
