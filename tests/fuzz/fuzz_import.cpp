// libFuzzer target: glTF/GLB import (tinygltf behind our URI and size checks, the JSON type check,
// Draco, PNG/JPEG decoding). The input is the scene file: a GLB when it starts with the magic,
// else glTF JSON (external buffers and images cannot exist, data: URIs can). Limits are lowered so
// that one input cannot take seconds or gigabytes.
#include <cstdint>
#include <cstring>

#include "io/gltf/import.h"
#include "tests/fuzz/fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string glb = gibake::fuzz::scratch_path("scene.glb");
  static const std::string gltf = gibake::fuzz::scratch_path("scene.gltf");
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::string& path = binary ? glb : gltf;
  if (!gibake::fuzz::write_input(path, data, size)) return 0;
  gibake::ImportOptions options;
  options.limits.max_file_bytes = uint64_t(4) << 20;
  options.limits.max_total_buffer_bytes = uint64_t(16) << 20;
  options.limits.max_image_dimension = 1024;
  options.limits.max_image_pixels = uint64_t(1) << 20;
  options.limits.max_total_pixels = uint64_t(1) << 22;
  options.limits.max_triangles = uint64_t(1) << 20;
  gibake::Context ctx;
  ctx.threads = 1;
  gibake::Scene scene;
  (void)gibake::import_scene(path, options, ctx, scene);
  return 0;
}
