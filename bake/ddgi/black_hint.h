// The warning for a bake that came out black everywhere, naming the likely cause: a scene with no
// light at all needs --sun, --sky, lights or emitters; a scene with light whose probes saw none sits
// them where light cannot reach (inside solids, sealed rooms).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "bake/scene/lights.h"
#include "io/scene.h"

namespace gibake {

struct BlackBakeFacts {
  int32_t probes = 0, inactive = 0;
  uint32_t inside_closed = 0;  // probes the closed-mesh check puts inside a closed solid (0 when it did not run)
  bool closed_mesh_checked = false;
};

// What light the scene and settings bring ("2 lights, --sun, emissive materials"); empty: none.
std::string scene_light_sources(const Scene& scene, const std::vector<SunLight>& suns,
                                const std::array<float, 3>& sky, const std::string& sky_hdr);

std::string black_bake_warning(const std::string& light_sources, const BlackBakeFacts& facts);

}  // namespace gibake
