// --check-camera: the views the reconstruction check takes its patches from (bake and verify), and
// --near-camera: the views whose surfaces get fine probes (bake; bake/ddgi/view_volume.h). Both take
// the same VIEW syntax; `option` names the option in errors.
#pragma once
#include <string>
#include <vector>

#include "bake/preview/preview.h"
#include "io/scene.h"
#include "io/status.h"

namespace gibake::cli {

// The check's block layout: a camera's view is split into the 8x8-pixel blocks of this size, as
// `preview --size 320x180 --check-patches` does.
constexpr int kCheckWidth = 320, kCheckHeight = 180;

// Each spec is `default` (the view `preview` shows without --camera: the glTF's first camera, else
// one framing the scene), `gltf:N` (the glTF's camera N) or `ex,ey,ez,tx,ty,tz,ux,uy,uz` (eye,
// target, up). Syntax alone, before the import:
Status check_camera_specs(const std::vector<std::string>& specs, float fov_deg, const char* option = "--check-camera",
                          const char* fov_option = "--check-fov");
// One spec as preview settings (the camera given, or the glTF camera's index, at the check's size).
Status check_view_settings(const std::string& spec, float fov_deg, PreviewSettings& s,
                           const char* option = "--check-camera");
// ... and the cameras themselves, once the scene is known (`fov_deg` 0: the glTF camera's, else 50).
Status resolve_check_cameras(const Scene& scene, const std::vector<std::string>& specs, float fov_deg,
                             std::vector<PreviewCamera>& out);

}  // namespace gibake::cli
