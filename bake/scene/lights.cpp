#include "bake/scene/lights.h"

namespace gibake {

std::vector<kernels::ShadeLight> shade_lights(const Scene& scene, const std::vector<SunLight>& suns) {
  std::vector<kernels::ShadeLight> lights;
  for (const Light& l : scene.lights) {
    const int type = l.type == Light::Type::Directional ? kernels::kLightDirectional
                     : l.type == Light::Type::Spot      ? kernels::kLightSpot
                                                        : kernels::kLightPoint;
    lights.push_back(kernels::make_shade_light(type, l.color, l.intensity, kernels::load3(l.position.data()),
                                               kernels::load3(l.direction.data()), l.range, l.inner_cone_angle,
                                               l.outer_cone_angle));
  }
  for (const SunLight& sun : suns)
    lights.push_back(kernels::make_shade_light(kernels::kLightDirectional, sun.color.data(), sun.lux,
                                               kernels::float3{}, kernels::load3(sun.direction.data()), 0.f, 0.f,
                                               0.f));
  return lights;
}

}  // namespace gibake
