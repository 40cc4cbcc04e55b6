#include "io/output/output_check.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <system_error>

namespace gibake {
namespace {

std::string folder_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// The canonical form of a path that may not exist yet: its existing prefix resolved (symlinks
// included), the rest normalised.
std::string canonical_or_normal(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec);
  return ec ? std::filesystem::path(path).lexically_normal().string() : p.string();
}

Status check_writable_target(const NamedPath& out) {
  struct stat st {};
  if (::stat(out.path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    return Status::error(ExitCode::IoFailure, out.path, out.option, "is a folder, not a file");
  // An output is written beside its target and renamed over it: a device or a FIFO would be
  // replaced by a regular file (as root, /dev/null's node itself).
  if (::stat(out.path.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    return Status::error(ExitCode::IoFailure, out.path, out.option,
                         "is a device, FIFO or socket, not a file: outputs replace their file whole");
  const std::string folder = folder_of(out.path);
  if (::stat(folder.c_str(), &st) != 0)
    return Status::error(ExitCode::IoFailure, out.path, out.option, "folder does not exist: " + folder);
  if (!S_ISDIR(st.st_mode))
    return Status::error(ExitCode::IoFailure, out.path, out.option, "not a folder: " + folder);
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    return Status::error(ExitCode::IoFailure, out.path, out.option, "folder is not writable: " + folder);
  return Status::ok();
}

}  // namespace

bool names_same_file(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  const bool ea = ::stat(a.c_str(), &sa) == 0, eb = ::stat(b.c_str(), &sb) == 0;
  if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (ea != eb) return false;
  return canonical_or_normal(a) == canonical_or_normal(b);
}

Status check_output_paths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  for (const NamedPath& out : outputs) GIBAKE_TRY(check_writable_target(out));
  for (size_t i = 0; i < outputs.size(); ++i) {
    for (size_t j = 0; j < i; ++j)
      if (names_same_file(outputs[i].path, outputs[j].path))
        return Status::error(ExitCode::BadArguments, outputs[i].path, outputs[i].option,
                             "names the same file as " + outputs[j].option + " (" + outputs[j].path +
                                 "); give each output its own file");
    for (const NamedPath& in : inputs)
      if (names_same_file(outputs[i].path, in.path))
        return Status::error(ExitCode::BadArguments, outputs[i].path, outputs[i].option,
                             "names a file this command reads (" + in.option + ": " + in.path +
                                 "); refusing to overwrite an input");
  }
  return Status::ok();
}

}  // namespace gibake
