// The emissive square of the voxel-GI tests: 1 m, 10 cd/m^2, facing down 2 m above a floor, and its
// exact on-axis irradiance (vxgi_analytic_test.cpp derives the formula and checks its limits).
#pragma once
#include <cmath>

#include "tests/bake/scene_builders.h"

namespace gibake::test {

// Irradiance on the axis of a square of side a and radiance L at distance h, facing it.
inline double square_irradiance(double a, double h, double L) {
  const double x = a / (2.0 * h), s = std::sqrt(1.0 + x * x);
  return 4.0 * L * x / s * std::atan(x / s);
}

// The square over a floor of the given albedo spanning [-half, half] in x and z.
inline Scene emissive_square_scene(float floor_albedo, float floor_half) {
  Scene scene;
  const int light = add_material(scene, 0.f, 10.f);
  add_quad(scene, {-0.5f, 2, -0.5f}, {0.5f, 2, -0.5f}, {0.5f, 2, 0.5f}, {-0.5f, 2, 0.5f}, {0, -1, 0}, light);
  const int floor = add_material(scene, floor_albedo);
  const float h = floor_half;
  add_quad(scene, {-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}, {0, 1, 0}, floor);
  return scene;
}

}  // namespace gibake::test
