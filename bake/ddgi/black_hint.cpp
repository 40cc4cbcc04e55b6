#include "bake/ddgi/black_hint.h"

namespace gibake {

std::string scene_light_sources(const Scene& scene, const std::vector<SunLight>& suns,
                                const std::array<float, 3>& sky, const std::string& sky_hdr) {
  std::vector<std::string> parts;
  if (!scene.lights.empty())
    parts.push_back(std::to_string(scene.lights.size()) + (scene.lights.size() == 1 ? " light" : " lights"));
  if (!suns.empty()) parts.push_back("--sun");
  if (!sky_hdr.empty() || sky[0] > 0.f || sky[1] > 0.f || sky[2] > 0.f) parts.push_back("a sky");
  for (const Material& m : scene.materials)
    if (m.is_emissive()) {
      parts.push_back("emissive materials");
      break;
    }
  std::string text;
  for (size_t i = 0; i < parts.size(); ++i) text += (i ? ", " : "") + parts[i];
  return text;
}

std::string black_bake_warning(const std::string& light_sources, const BlackBakeFacts& f) {
  if (light_sources.empty())
    return "the bake is black everywhere: the scene has no light (add --sun, --sky, lights or emissive materials)";
  std::string where = std::to_string(f.inactive) + " of " + std::to_string(f.probes) + " probes are inactive";
  if (f.closed_mesh_checked)
    where += ", " + std::to_string(f.inside_closed) + " lie inside closed solids";
  if (f.probes == 1) where += "; the grid is one probe at the centre of the scene bounds, often inside the model";
  return "the bake is black everywhere although the scene has light (" + light_sources +
         "): no light reached any probe that is sampled (" + where +
         "); probes inside solids or sealed rooms see none: check where they sit (gibake preview --mode probes) or "
         "place the grid with --probe-counts, --grid-min and --grid-max";
}

}  // namespace gibake
