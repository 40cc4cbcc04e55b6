// Makefile-style dependency files (`gibake bake --depfile`), read by Ninja and Make.
#pragma once
#include <string>
#include <vector>

#include "io/status.h"

namespace gibake {

// Escapes a path for a Makefile rule as Make and Ninja read it: spaces and '#' with a backslash
// (the backslashes just before them doubled), '$' as '$$'.
std::string depfile_escape(const std::string& path);

// The first character of `path` that no escape makes readable to both Make and Ninja (a newline,
// CR, tab, ':', ';', '%' or '='), or 0.
char depfile_unwritable(const std::string& path);
// Such a character named for a message: "a tab", "':'".
std::string depfile_char_name(char c);
// An input as the depfile names it: absolute, normalised (the path as given where that fails).
std::string depfile_input_path(const std::string& path);

// Writes "<target>: <input> <input> ..." to `depfile_path`, atomically (temp file + rename), then an
// empty rule for each input, as `gcc -MP` does: Make stops at a prerequisite that does not exist
// and has no rule, and with the empty rule it bakes again instead (Ninja reads both forms). The
// target as given (a build system names its output so: a relative name stays relative), the inputs
// made absolute, each once. A path holding a character depfile_unwritable names is refused (BadArguments):
// the rule would not read back.
Status write_depfile(const std::string& depfile_path, const std::string& target,
                     const std::vector<std::string>& inputs);

}  // namespace gibake
