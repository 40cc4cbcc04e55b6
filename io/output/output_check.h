// Every output path of a command, checked before any work starts: a bake must not run for minutes
// only to find it cannot write its result, and no output may land on another output or on a file
// the command reads. Files are compared by identity (device and inode where the file exists, so a
// hard link or a symlink to it is the same file; the canonical path otherwise).
#pragma once
#include <string>
#include <vector>

#include "io/status.h"

namespace gibake {

// A path as the user gave it, with the option (or the role) that named it, for the message.
struct NamedPath {
  std::string option;  // "--out", "--voxels", "scene", "buffers[0]" ...
  std::string path;
};

// Checks, in order, for every output: not a folder, its folder exists and is writable (exit 2);
// then no two outputs name one file and no output names an input (exit 1, BadArguments).
// The Status names the output path and the option that gave it. Writes nothing.
Status check_output_paths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);

// Whether two paths name one file: device and inode when both exist, canonical paths when neither
// does (a path that exists and one that does not are different files).
bool names_same_file(const std::string& a, const std::string& b);

}  // namespace gibake
