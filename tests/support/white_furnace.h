// The white furnace of the reconstruction tests: a closed box [-1, 1]^3 of albedo kFurnaceRho
// emitting kFurnaceLe inward. With path gather and no roulette, radiance is
// Le sum_{k <= bounces+1} rho^k everywhere, at the probes and at every wall point, whatever the
// probes: a check's ratio against the path-traced truth is 1 up to noise.
#pragma once
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "bake/preview/reconstruction_check.h"
#include "tests/bake/scene_builders.h"
#include "tests/support/probe_grid.h"

namespace gibake::test {

constexpr float kFurnaceRho = 0.7f, kFurnaceLe = 1.f;
constexpr int kFurnaceBounces = 3;

// The box, prepared for tracing, and its texture mips (none: a single colour).
struct FurnaceBox {
  Scene scene;
  std::unique_ptr<PreparedScene> prepared;
  TextureLod lod;
};

inline void add_furnace_box(FurnaceBox& f) {
  add_box(f.scene, {-1, -1, -1}, {1, 1, 1}, /*inward=*/true, add_material(f.scene, kFurnaceRho, kFurnaceLe));
}

inline void prepare_furnace_box(FurnaceBox& f) {
  ASSERT_TRUE(PreparedScene::create(f.scene, Context{}, f.prepared));
  f.lod = TextureLod(f.scene, Context{});
}

// A furnace bake: n^3 probes from lo to hi, 256 rays, kFurnaceBounces bounces, paths that roulette
// does not cut short, no CGAL check.
inline DdgiSettings furnace_probes(const Vec3f& lo, const Vec3f& hi, int32_t n) {
  DdgiSettings s = probe_grid(lo, hi, {n, n, n}, 256);
  s.bounces = kFurnaceBounces;
  s.roulette_depth = 16;
  s.cgal_check = false;
  return s;
}

// The check against it: `patches` patches, 64 reference paths a point ending where the bake's do.
inline ReconstructionSettings furnace_check(uint32_t patches) {
  ReconstructionSettings rs;
  rs.patches = patches;
  rs.rays = 64;
  rs.bounces = kFurnaceBounces;
  rs.roulette_depth = 16;
  return rs;
}

}  // namespace gibake::test
