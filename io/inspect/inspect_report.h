// `gibake inspect`: what the importer sees in a scene, as JSON or text.
// The CLI only parses arguments and prints; everything else lives here.
#pragma once
#include <string>

#include "io/context.h"
#include "io/gltf/import.h"
#include "io/inspect/mesh_diagnostics.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake {

struct InspectOptions {
  bool load_textures = true;  // false: texture sizes are whatever the importer fills in
  bool check_self_intersections = false;
  ImportLimits limits;
};

struct InspectResult {
  Scene scene;
  MeshDiagnostics diagnostics;
};

// Imports `path` (warnings go to ctx) and runs the mesh diagnostics on the whole scene.
Status inspect_scene(const std::string& path, const InspectOptions& options, const Context& ctx,
                     InspectResult& out);

// The report as one JSON object (pretty-printed, UTF-8, ends with a newline). Invalid UTF-8 in
// names is replaced, non-finite numbers become null, so the output always parses.
std::string inspect_report_json(const Scene& scene, const MeshDiagnostics& diagnostics);
// The same facts for humans.
std::string inspect_report_text(const Scene& scene, const MeshDiagnostics& diagnostics);

// Names used in both reports.
const char* alpha_mode_name(AlphaMode mode);         // "OPAQUE", "MASK", "BLEND"
const char* light_type_name(Light::Type type);       // "directional", "point", "spot"
const char* light_intensity_unit(Light::Type type);  // "lux" or "cd"

}  // namespace gibake
