// glTF 2.0 / GLB import (KHR_draco_mesh_compression, KHR_lights_punctual, KHR_texture_transform,
// KHR_materials_emissive_strength, KHR_mesh_quantization) into a world-space Scene.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "io/context.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

// Caps that keep hostile files from exhausting memory; each breach is an InvalidInput error.
struct ImportLimits {
  uint64_t max_file_bytes = uint64_t(2) << 30;          // any single file read (scene, buffer, image)
  uint64_t max_total_buffer_bytes = uint64_t(4) << 30;  // sum of all buffers
  uint32_t max_image_dimension = 16384;                 // width or height
  uint64_t max_image_pixels = uint64_t(1) << 26;        // one image (64 Mpx)
  uint64_t max_total_pixels = uint64_t(1) << 29;        // all images together
  uint64_t max_triangles = uint64_t(1) << 28;           // after instancing
  double max_coordinate = kMaxSceneCoordinate;          // world space, vertices, lights and cameras (scene.h)
};

struct ImportOptions {
  ImportLimits limits;
  bool load_textures = true;  // inspect may skip decoding pixels
  // Polled between images and between nodes: true stops the import (a failure the caller replaces
  // with its own reason; `gibake bake --backend vulkan` when the driver lists no such device).
  std::function<bool()> cancelled;
};

// Loads `path` (.gltf or .glb). On failure `out` is left empty and the Status names the file,
// the place in it (e.g. "accessors[3]") and the problem.
Status import_scene(const std::string& path, const ImportOptions& options, const Context& ctx,
                    Scene& out);

}  // namespace gibake
