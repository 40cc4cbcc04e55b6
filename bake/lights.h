// The light list the bakers evaluate: the scene's KHR_lights_punctual lights followed by the
// --sun lights, as kernels::ShadeLight (photometric: lux for directional, candela otherwise).
#pragma once
#include <vector>

#include "bake/ddgi.h"
#include "io/scene.h"
#include "kernels/shade.h"

namespace gibake {

std::vector<kernels::ShadeLight> shade_lights(const Scene& scene, const std::vector<SunLight>& suns);

}  // namespace gibake
