// The layer of probes outside an open side (bake/ddgi/probe_fit.h), judged by light whose answer is
// known without the bake: a room open at the front, lit by a lamp on its ceiling, in a black world
// (no sky, nothing outside). The slabs' front faces at the opening look out into that world: their
// irradiance is exactly 0. A lattice inside the room reads them from probes behind them, which see
// the lit inside; with the layer in front of the opening the loader's sampler reads them from
// probes that look out. The same bake without the layer (its grid minus the outer layer, given
// explicitly) shows what the layer mends.
#include <gtest/gtest.h>

#include <cstdio>

#include "bake/ddgi/ddgi.h"
#include "bake/pipeline/devices.h"
#include "gibake/loader.hpp"
#include "tests/bake/loader_file.h"
#include "tests/bake/scene_builders.h"

namespace gibake {
namespace {

Scene lit_open_room() {
  Scene scene = test::open_front_room(0.7f);
  test::add_quad(scene, {1.5f, 3.99f, 1.5f}, {2.5f, 3.99f, 1.5f}, {2.5f, 3.99f, 2.5f}, {1.5f, 3.99f, 2.5f}, {0, -1, 0},
                 test::add_material(scene, 0.f, 20.f));
  return scene;
}

DdgiSettings settings() {
  DdgiSettings s;
  s.rays = 256;
  s.target_error = 0.f;
  s.bounces = 2;
  s.cgal_check = false;
  return s;
}

float luminance(const loader::Rgb& e) { return 0.2126f * e[0] + 0.7152f * e[1] + 0.0722f * e[2]; }

struct Readings {
  float rim = 0.f, floor = 0.f;  // lux, summed over the points below
};

// The points below read from one bake, each probe's irradiance from its atlas or from its SH.
Readings read(const loader::BakeFile& file, bool atlas) {
  Readings r;
  loader::SampleOptions o;
  o.use_irradiance_atlas = atlas;
  for (float x : {0.5f, 1.f, 2.f, 3.f, 3.5f}) {
    loader::Rgb e{};
    file.sample_ddgi({x, -0.05f, 4.f}, {0.f, 0.f, 1.f}, e, o);  // the floor slab's front face
    r.rim += luminance(e);
    file.sample_ddgi({-0.05f, x, 4.f}, {0.f, 0.f, 1.f}, e, o);  // the left wall's
    r.rim += luminance(e);
    file.sample_ddgi({x, 0.f, 3.5f}, {0.f, 1.f, 0.f}, e, o);  // the floor inside, near the opening
    r.floor += 2.f * luminance(e);
  }
  return r;
}

struct Baked {
  Readings atlas, sh;
  DdgiVolumeDesc desc{};
};

Baked bake(const Scene& scene, const DdgiSettings& s) {
  DdgiResult result;
  DdgiReport report;
  EXPECT_TRUE(bake_ddgi(scene, s, Context{}, result, report).is_ok());
  loader::BakeFile file;
  test::open_in_loader(result, file);
  return {read(file, true), read(file, false), result.desc};
}

TEST(OpenSideLight, FacesLookingOutOfAnOpenSideReadTheirBlackWorld) {
  const Scene scene = lit_open_room();
  const Baked baked = bake(scene, settings());
  const Readings& with = baked.atlas;
  const Readings& sh = baked.sh;
  const DdgiVolumeDesc& d = baked.desc;
  ASSERT_EQ(d.counts[2], 17);  // 16 in the room and the layer in front of it (probe_fit_test.cpp)
  DdgiSettings without = settings();
  without.grid.explicit_bounds = true;
  without.grid.grid_min = d.grid_min;
  without.grid.grid_max = {d.grid_max[0], d.grid_max[1], d.grid_max[2] - d.spacing[2]};
  without.grid.counts = {d.counts[0], d.counts[1], d.counts[2] - 1};
  const Readings inside = bake(scene, without).atlas;
  std::printf("rim / floor: with the layer %.4f (from the SH %.4f), without %.4f (floor %.1f and %.1f lux)\n",
              with.rim / with.floor, sh.rim / sh.floor, inside.rim / inside.floor, with.floor / 10, inside.floor / 10);
  // The truth is 0: with the layer the rim gets a small share of the floor's light (the test prints
  // the figures); without it, light leaks in through the open side, four times as much. Read from
  // the irradiance atlas (the default) the layer's probes leave a little: the texels nearest the
  // rim's normal look about 13 degrees aside and catch the lit inside at grazing angles. Read from
  // their SH, whose first band cancels light from far behind a face, they leave almost none.
  ASSERT_GT(with.floor, 0.f);
  EXPECT_LT(with.rim, 0.03f * with.floor);
  EXPECT_LT(sh.rim, 0.005f * sh.floor);
  EXPECT_GT(inside.rim, 0.06f * inside.floor);  // what the layer mends
  EXPECT_GT(inside.rim, 3.f * with.rim);
  EXPECT_NEAR(with.floor / inside.floor, 1.f, 0.1f);  // and the room inside reads as before
}

}  // namespace
}  // namespace gibake
