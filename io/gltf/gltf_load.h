// Reads a .gltf/.glb into a tinygltf::Model with confined file access, capped sizes and our own
// image decoding. tinygltf's implementation is compiled in gltf_load.cpp only.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "io/context.h"
#include "io/gltf/gltf_tiny.h"
#include "io/gltf/import.h"
#include "io/status.h"

namespace gibake::gltf {

// On success `model` holds the parsed document, buffers loaded and images decoded to RGBA8
// (Image::image, component 4, bits 8; empty when undecodable or options.load_textures is false),
// `files_read` every external file read (the scene file first) and `files_missing` the image files
// it names inside its folder that do not exist (each warned and ignored).
// `beside`, when given, runs on the calling thread once the document is parsed, while the images
// decode on the other threads: work that reads no pixels (the mesh conversion), keeping its own
// status. An exception it throws is rethrown once the decode has finished.
Status load_model(const std::string& path, const ImportOptions& options, const Context& ctx, tinygltf::Model& model,
                  std::vector<std::string>& files_read, std::vector<std::string>& files_missing,
                  const std::function<void()>& beside = {});

}  // namespace gibake::gltf
