// Makefile-style dependency files (`gibake bake --depfile`), read by Ninja and Make.
#pragma once
#include <string>
#include <vector>

#include "io/status.h"

namespace gibake {

// Escapes a path for a Makefile rule: spaces and '#' with a backslash, '$' as '$$'.
std::string depfile_escape(const std::string& path);

// Writes "<target>: <input> <input> ..." to `depfile_path`, atomically (temp file + rename).
Status write_depfile(const std::string& depfile_path, const std::string& target,
                     const std::vector<std::string>& inputs);

}  // namespace gibake
