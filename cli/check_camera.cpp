#include "cli/check_camera.h"

#include <cstdlib>

#include "cli/options.h"

namespace gibake::cli {

Status check_view_settings(const std::string& spec, float fov_deg, PreviewSettings& s, const char* option) {
  s.width = kCheckWidth;
  s.height = kCheckHeight;
  s.fov_deg = fov_deg;
  if (spec == "default") return Status::ok();
  if (spec.rfind("gltf:", 0) == 0) {
    const std::string index = spec.substr(5);
    char* end = nullptr;
    const unsigned long n = index.empty() ? 0 : std::strtoul(index.c_str(), &end, 10);
    if (index.empty() || *end != '\0' || index[0] == '-' || n > 65535)
      return bad_arg(option, "expected gltf:N with a camera index N, got '" + spec + "'");
    s.camera_index = size_t(n);
    return Status::ok();
  }
  std::vector<double> d;
  if (!parse_numbers(spec, ',', 9, d))
    return bad_arg(
        option,
        "expected 'default', 'gltf:N' or eye,target,up as 9 numbers ex,ey,ez,tx,ty,tz,ux,uy,uz, got '" + spec + "'");
  GIBAKE_TRY(check_places(option, d, 0, 6, spec));
  GIBAKE_TRY(check_view_vectors(option, d, spec));
  s.camera_given = true;
  s.eye = {float(d[0]), float(d[1]), float(d[2])};
  s.target = {float(d[3]), float(d[4]), float(d[5])};
  s.up = {float(d[6]), float(d[7]), float(d[8])};
  return Status::ok();
}

Status check_camera_specs(const std::vector<std::string>& specs, float fov_deg, const char* option,
                          const char* fov_option) {
  if (!(fov_deg >= 0.f && fov_deg < 179.f))
    return bad_arg(fov_option, "expected degrees below 179 (0: the glTF camera's, else 50)");
  if (fov_deg > 0.f && specs.empty())
    return bad_arg(fov_option, std::string("only with ") + option + " (the view it widens)");
  for (const std::string& spec : specs) {
    PreviewSettings s;
    GIBAKE_TRY(check_view_settings(spec, fov_deg, s, option));
  }
  return Status::ok();
}

Status resolve_check_cameras(const Scene& scene, const std::vector<std::string>& specs, float fov_deg,
                             std::vector<PreviewCamera>& out) {
  out.clear();
  for (const std::string& spec : specs) {
    PreviewSettings s;
    GIBAKE_TRY(check_view_settings(spec, fov_deg, s));
    if (!s.camera_given && spec != "default" && s.camera_index >= scene.cameras.size())
      return bad_arg("--check-camera",
                     spec + ": the scene has " + std::to_string(scene.cameras.size()) + " glTF camera(s)");
    PreviewCamera cam;
    std::string described;
    GIBAKE_TRY(resolve_camera(scene, s, cam, described));
    out.push_back(cam);
  }
  return Status::ok();
}

}  // namespace gibake::cli
