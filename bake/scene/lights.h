// The light list the bakers evaluate: the scene's KHR_lights_punctual lights followed by the
// --sun lights, as kernels::ShadeLight (photometric: lux for directional, candela otherwise).
#pragma once
#include <array>
#include <vector>

#include "io/scene.h"
#include "kernels/shade.h"

namespace gibake {

// A directional light added on the command line (--sun). `direction` is the direction the
// light TRAVELS (e.g. 0,-1,0 = noon sun shining straight down), like glTF lights' -Z axis.
struct SunLight {
  std::array<float, 3> direction{0.f, -1.f, 0.f};
  float lux = 0.f;
  std::array<float, 3> color{1.f, 1.f, 1.f};
};

std::vector<kernels::ShadeLight> shade_lights(const Scene& scene, const std::vector<SunLight>& suns);

}  // namespace gibake
