// BakeFile::sample_ddgi, the blend of several DDGI volumes (docs/FORMAT.md "Several volumes"):
// expected values computed here from the rule as written (a volume's weight per axis is 1 up to half
// a spacing outside its probe box, 0 from one spacing outside, linear between), not through the
// loader's blend_weight.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "gibake/loader.hpp"
#include "multi_volume.h"
#include "synthetic.h"

namespace {

using namespace gibake;
using loader::Rgb;
using loader::Vec3;

DdgiResult volume(int n, Vec3 grid_min, float spacing, uint32_t seed) {
  DdgiResult r = test::make_ddgi(n, n, n, 2, seed);
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = grid_min[a];
    r.desc.spacing[a] = spacing;
    r.desc.grid_max[a] = grid_min[a] + spacing * float(n - 1);
  }
  // make_ddgi's every fifth probe inactive is the whole last x layer when n is 5: spread them.
  for (size_t p = 0; p < r.states.size(); ++p) r.states[p] = p % 7 == 3 ? ProbeState::Inactive : ProbeState::Active;
  return r;
}

loader::BakeFile open_volumes(const std::vector<const DdgiResult*>& v, std::vector<uint8_t>& bytes) {
  BakeFileOptions o;
  o.atlas = FloatPrecision::Full;
  const Status st = test::multi_volume_bytes(v, o, bytes);
  EXPECT_TRUE(st.is_ok()) << st.message();
  loader::BakeFile file;
  const loader::Error e = file.open_borrowed(bytes.data(), bytes.size());
  EXPECT_FALSE(e) << e.message;
  return file;
}

// The rule's weight, from the description: per axis the distance outside the probe box in spacings,
// d, gives (1 - d) / 0.5 clamped to [0, 1]; the product over the axes.
float expected_weight(const gibake_ddgi_volume& d, const Vec3& p) {
  double w = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double out = std::max({double(d.grid_min[a]) - p[a], double(p[a]) - d.grid_max[a], 0.0}) / d.spacing[a];
    w *= std::clamp((1.0 - out) / 0.5, 0.0, 1.0);
  }
  return float(w);
}

Vec3 unit(float x, float y, float z) {
  const float l = std::sqrt(x * x + y * y + z * z);
  return {x / l, y / l, z / l};
}

bool same_bits(const Rgb& a, const Rgb& b) { return std::memcmp(a.data(), b.data(), sizeof a) == 0; }

Rgb answer(const loader::DdgiVolume& v, const Vec3& p, const Vec3& n, const loader::SampleOptions& o = {}) {
  Rgb e;
  EXPECT_TRUE(v.try_sample_irradiance(p, n, e, o)) << "no answer at " << p[0] << "," << p[1] << "," << p[2];
  return e;
}

// DDGI's back-face weights, without the sampler's fade behind the point: the synthetic volumes'
// random depth moments hide some of their probes, and with the fade too a volume would leave a few
// points unseen, which the tests of the blend's sight cover. The tests of the blend's arithmetic
// over volumes that see their points use these.
loader::SampleOptions ddgi_weights() {
  loader::SampleOptions o;
  o.behind_fade = 0.f;
  return o;
}

// A coarse volume (probe box [0, 8]^3, spacing 2) holding a fine one (probe box [2, 4]^3, spacing
// 0.5: weight 1 in [1.75, 4.25]^3, 0 outside [1.5, 4.5]^3), the fine one second in the file:
// priority must put it first.
class Nested : public ::testing::Test {
 protected:
  void SetUp() override {
    coarse_ = volume(5, {0.f, 0.f, 0.f}, 2.f, 401);
    fine_ = volume(5, {2.f, 2.f, 2.f}, 0.5f, 402);
    file_ = open_volumes({&coarse_, &fine_}, bytes_);
    ASSERT_EQ(file_.ddgi_volumes().size(), 2u);
  }
  const loader::DdgiVolume& coarse() const { return file_.ddgi_volumes()[0]; }
  const loader::DdgiVolume& fine() const { return file_.ddgi_volumes()[1]; }
  DdgiResult coarse_, fine_;
  std::vector<uint8_t> bytes_;
  loader::BakeFile file_;
};

TEST_F(Nested, PriorityIsFinestFirst) {
  ASSERT_EQ(file_.ddgi_priority().size(), 2u);
  EXPECT_EQ(file_.ddgi_priority()[0], 1u);
  EXPECT_EQ(file_.ddgi_priority()[1], 0u);
}

TEST_F(Nested, DeepInsideTheFinerVolumeItWinsExactly) {
  const loader::SampleOptions o = ddgi_weights();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(1.76f, 4.24f);  // weight 1 in the fine volume
  int compared = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng)}, n = unit(u(rng) - 3.f, 1.f, u(rng) - 3.f);
    ASSERT_FLOAT_EQ(expected_weight(fine().desc(), p), 1.f);
    Rgb fine_e, out;
    if (!fine().try_sample_irradiance(p, n, fine_e, o)) continue;
    ASSERT_TRUE(file_.sample_ddgi(p, n, out, o));
    EXPECT_TRUE(same_bits(out, fine_e)) << i;
    EXPECT_FALSE(same_bits(out, coarse().sample_irradiance(p, n, o))) << i;  // the coarse one differs
    ++compared;
  }
  EXPECT_GT(compared, 200);
}

TEST_F(Nested, OutsideTheFinerVolumeTheCoarseOneAnswersAlone) {
  for (const Vec3& p : {Vec3{0.5f, 0.5f, 0.5f}, Vec3{1.45f, 3.f, 3.f}, Vec3{4.6f, 2.f, 8.9f}, Vec3{-0.9f, 8.f, 1.f},
                        Vec3{8.95f, 4.f, 4.f}}) {
    const Vec3 n = unit(0.3f, 1.f, -0.2f);
    ASSERT_FLOAT_EQ(expected_weight(fine().desc(), p), 0.f);
    Rgb out;
    ASSERT_TRUE(file_.sample_ddgi(p, n, out));
    EXPECT_TRUE(same_bits(out, coarse().sample_irradiance(p, n)));
  }
}

// In the fine volume's fade band (the coarse weight is 1 there): w E_fine + (1 - w) E_coarse.
TEST_F(Nested, FadeBandIsTheConvexCombination) {
  const loader::SampleOptions o = ddgi_weights();
  int checked = 0;
  for (const Vec3& p : {Vec3{1.6f, 3.f, 3.f}, Vec3{1.7f, 1.55f, 4.4f}, Vec3{4.3f, 3.3f, 2.6f}, Vec3{3.f, 2.2f, 1.65f},
                        Vec3{3.1f, 4.45f, 3.f}}) {
    const float w = expected_weight(fine().desc(), p);
    ASSERT_GT(w, 0.f);
    ASSERT_LT(w, 1.f);
    ASSERT_FLOAT_EQ(expected_weight(coarse().desc(), p), 1.f);
    for (const Vec3& n : {unit(0, 1, 0), unit(-1, 0.2f, 0.4f), unit(0.1f, -1.f, 0.7f)}) {
      const Rgb f = answer(fine(), p, n, o), c = answer(coarse(), p, n, o);
      Rgb out;
      ASSERT_TRUE(file_.sample_ddgi(p, n, out, o));
      for (int k = 0; k < 3; ++k) {
        const float e = w * f[k] + (1.f - w) * c[k];
        EXPECT_NEAR(out[k], e, 1e-5f * std::max({1.f, f[k], c[k]})) << "w " << w << " channel " << k;
      }
      EXPECT_GT(std::fabs(f[0] - c[0]), 1e-2f * std::max(f[0], c[0]));  // the two differ: the test can fail
      ++checked;
    }
  }
  EXPECT_EQ(checked, 15);
}

// A finer volume without a usable probe (all inactive) is skipped: the coarse one answers.
TEST(Blend, AVolumeWithoutAnAnswerIsSkipped) {
  DdgiResult coarse = volume(5, {0.f, 0.f, 0.f}, 2.f, 411), fine = volume(4, {2.f, 2.f, 2.f}, 0.5f, 412);
  std::fill(fine.states.begin(), fine.states.end(), ProbeState::Inactive);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&coarse, &fine}, bytes);
  const Vec3 p{2.6f, 2.7f, 2.8f}, n = unit(0.2f, 1.f, 0.f);
  Rgb none, out;
  EXPECT_FALSE(file.ddgi_volumes()[1].try_sample_irradiance(p, n, none));
  EXPECT_FLOAT_EQ(expected_weight(file.ddgi_volumes()[1].desc(), p), 1.f);
  ASSERT_TRUE(file.sample_ddgi(p, n, out));
  EXPECT_TRUE(same_bits(out, file.ddgi_volumes()[0].sample_irradiance(p, n)));
  EXPECT_GT(out[0], 0.f);
}

// A finer volume whose probes barely see the point (each probe's depth moments put an occluder 2 cm
// away, so the Chebyshev weight is near 0 at every corner) takes its blend weight times its sight
// over GIBAKE_DDGI_FULL_SIGHT, the coarse one the rest: the point is passed on, not answered with
// the floor's weights, and the mix is continuous as the sight falls. The fine volume alone still
// answers with its own bits.
TEST(Blend, AVolumeWhoseProbesDoNotSeeThePointPassesItOn) {
  DdgiResult coarse = volume(5, {0.f, 0.f, 0.f}, 2.f, 461), fine = volume(4, {2.f, 2.f, 2.f}, 0.5f, 462);
  for (size_t i = 0; i + 1 < fine.depth_atlas.size(); i += 2)
    fine.depth_atlas[i] = 0.02f, fine.depth_atlas[i + 1] = 4e-4f;
  for (size_t i = 0; i + 1 < coarse.depth_atlas.size(); i += 2)
    coarse.depth_atlas[i] = 30.f, coarse.depth_atlas[i + 1] = 900.f;  // sees every point
  std::vector<uint8_t> bytes, alone_bytes;
  const loader::BakeFile file = open_volumes({&coarse, &fine}, bytes);
  const loader::BakeFile alone = open_volumes({&fine}, alone_bytes);
  const loader::DdgiVolume &c = file.ddgi_volumes()[0], &f = file.ddgi_volumes()[1];
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(1.8f, 3.7f);  // the fine volume's weight is 1 here
  std::normal_distribution<float> g(0.f, 1.f);
  int checked = 0, passed_on = 0, differ = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng)}, n = unit(g(rng), g(rng), g(rng));
    ASSERT_FLOAT_EQ(expected_weight(f.desc(), p), 1.f);
    Rgb ef, ec, out;
    float coarse_sight = 0.f;  // below full where the active coarse probes all lie behind the point
    if (!f.try_sample_irradiance(p, n, ef) || !c.try_sample_irradiance(p, n, ec, coarse_sight)) continue;
    if (coarse_sight < GIBAKE_DDGI_FULL_SIGHT) continue;
    loader::ProbeWeight w[8];
    const uint32_t count = f.probe_weights(p, n, w);
    float sight = 0.f;
    for (uint32_t k = 0; k < count; ++k) sight = std::max(sight, w[k].backface * w[k].visibility);
    ASSERT_LT(sight, GIBAKE_DDGI_FULL_SIGHT);
    const float share = sight / GIBAKE_DDGI_FULL_SIGHT;
    passed_on += share < 0.01f;
    ASSERT_TRUE(file.sample_ddgi(p, n, out));
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(out[k], share * ef[k] + (1.f - share) * ec[k], 1e-5f * std::max({1.f, ef[k], ec[k]})) << i;
    differ += std::fabs(ef[0] - ec[0]) > 0.1f * std::max(ef[0], ec[0]);
    Rgb lone;
    ASSERT_TRUE(alone.sample_ddgi(p, n, lone));
    EXPECT_TRUE(same_bits(lone, ef)) << i;
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(passed_on, checked / 2);  // most points: the coarse volume's answer within 1%
  EXPECT_GT(differ, checked / 2);     // the two answers differ by 10% or more: the test can fail
}

// Two volumes of equal spacing side by side, 1.2 spacings apart, their fade bands overlapping: the
// first in the file comes first; where both are in their fade bands only, the sum is normalised.
TEST(Blend, FadeBandsOnlyAreNormalisedAndTiesKeepFileOrder) {
  const loader::SampleOptions o = ddgi_weights();
  DdgiResult a = volume(3, {20.f, 0.f, 0.f}, 1.f, 421), b = volume(3, {23.2f, 0.f, 0.f}, 1.f, 422);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&a, &b}, bytes);
  ASSERT_EQ(file.ddgi_priority(), (std::vector<uint32_t>{0u, 1u}));
  const loader::DdgiVolume &va = file.ddgi_volumes()[0], &vb = file.ddgi_volumes()[1];
  for (const Vec3& p : {Vec3{22.6f, 1.f, 1.f}, Vec3{22.55f, 1.2f, 2.7f}, Vec3{22.65f, -0.6f, 2.3f}}) {
    const Vec3 n = unit(0.f, 1.f, 0.3f);
    const float wa = expected_weight(va.desc(), p), wb = expected_weight(vb.desc(), p);
    ASSERT_GT(wa, 0.f);
    ASSERT_GT(wb, 0.f);
    ASSERT_LT(wa + wb * (1.f - wa), 1.f);
    const float ca = wa, cb = wb * (1.f - wa);
    const Rgb ea = answer(va, p, n, o), eb = answer(vb, p, n, o);
    Rgb out;
    ASSERT_TRUE(file.sample_ddgi(p, n, out, o));
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(out[k], (ca * ea[k] + cb * eb[k]) / (ca + cb), 1e-5f * std::max({1.f, ea[k], eb[k]}));
  }
  // Only one of them: its own answer, to the bit, in its fade band too.
  for (const Vec3& p : {Vec3{19.2f, 1.f, 1.f}, Vec3{21.f, 2.8f, -0.9f}, Vec3{22.3f, 1.f, 1.f}, Vec3{25.9f, 1.f, 1.f}}) {
    const Vec3 n = unit(1.f, 0.5f, 0.f);
    const loader::DdgiVolume& only = p[0] < 22.5f ? va : vb;
    Rgb out;
    ASSERT_TRUE(file.sample_ddgi(p, n, out, o));
    EXPECT_TRUE(same_bits(out, only.sample_irradiance(p, n, o)));
  }
}

// Outside every region: false, and the nearest volume's clamped answer.
TEST(Blend, OutsideEveryVolumeIsFalse) {
  DdgiResult a = volume(3, {0.f, 0.f, 0.f}, 1.f, 431), b = volume(3, {10.f, 0.f, 0.f}, 0.5f, 432);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&a, &b}, bytes);
  const Vec3 n = unit(0, 1, 0);
  for (const Vec3& p : {Vec3{5.f, 1.f, 1.f}, Vec3{-1.1f, 1.f, 1.f}, Vec3{1.f, 1.f, 3.1f}, Vec3{1e4f, 0.f, 0.f},
                        Vec3{11.f, 1.f, 1.6f}}) {
    Rgb out;
    EXPECT_FALSE(file.sample_ddgi(p, n, out)) << p[0] << "," << p[1] << "," << p[2];
    const loader::DdgiVolume& nearest = p[0] < 5.5f ? file.ddgi_volumes()[0] : file.ddgi_volumes()[1];
    EXPECT_TRUE(same_bits(out, nearest.sample_irradiance(p, n)));
  }
  Rgb out;
  EXPECT_TRUE(file.sample_ddgi({-0.99f, 1.f, 1.f}, n, out));  // just inside the region
}

// One volume: exactly sample_irradiance everywhere, true exactly inside the region.
TEST(Blend, OneVolumeIsItsSamplerToTheBit) {
  DdgiResult r = test::make_ddgi(4, 3, 5, 2, 441);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&r}, bytes);
  const loader::DdgiVolume& v = file.ddgi_volumes()[0];
  const gibake_ddgi_volume& d = v.desc();
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-0.3f, 1.3f);
  std::normal_distribution<float> g(0.f, 1.f);
  int inside = 0;
  for (int i = 0; i < 2000; ++i) {
    Vec3 p;
    bool in = true;
    for (int a = 0; a < 3; ++a) {
      const float lo = d.grid_min[a] - d.spacing[a], hi = d.grid_max[a] + d.spacing[a];
      p[a] = lo + u(rng) * (hi - lo);
      in = in && p[a] >= lo && p[a] <= hi;
    }
    const Vec3 n = unit(g(rng), g(rng), g(rng));
    Rgb out;
    EXPECT_EQ(file.sample_ddgi(p, n, out), in) << i;
    EXPECT_TRUE(same_bits(out, v.sample_irradiance(p, n))) << i;
    inside += in;
  }
  EXPECT_GT(inside, 300);  // (1 / 1.6)^3 of the points lie inside the region
  EXPECT_LT(inside, 700);
}

// Two overlapping volumes of the same constant radiance: the blend keeps the constant everywhere
// (a blend whose weights do not sum to 1 after normalisation, or that adds instead of taking what is
// left, changes it in the bands). E = pi x L for a uniform L (sh_irradiance of c0 = L / Y00).
TEST(Blend, ConstantRadianceStaysConstant) {
  const float radiance = 3.f;  // cd/m^2, every direction
  auto constant = [&](DdgiResult& r) {
    const int c = r.desc.sh_coefficients();
    for (size_t i = 0; i < r.sh.size(); ++i) r.sh[i] = (i / 3) % size_t(c) == 0 ? radiance / 0.282095f : 0.f;
    for (size_t i = 0; i < r.irradiance_atlas.size(); ++i)  // E = pi L in every direction, alpha 1
      r.irradiance_atlas[i] = i % 4 == 3 ? 1.f : 3.14159265f * radiance;
    std::fill(r.states.begin(), r.states.end(), ProbeState::Active);  // an answer everywhere
  };
  DdgiResult a = volume(4, {0.f, 0.f, 0.f}, 1.f, 451), b = volume(5, {1.3f, 0.7f, 1.1f}, 0.4f, 452);
  constant(a);
  constant(b);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&a, &b}, bytes);
  const float expected = 3.14159265f * radiance;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.9f, 3.9f);  // into the coarse volume's fade band too
  std::normal_distribution<float> g(0.f, 1.f);
  int both = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng)}, n = unit(g(rng), g(rng), g(rng));
    Rgb out, sh;
    ASSERT_TRUE(file.sample_ddgi(p, n, out));
    loader::SampleOptions from_sh;
    from_sh.use_irradiance_atlas = false;
    ASSERT_TRUE(file.sample_ddgi(p, n, sh, from_sh));
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(out[k], expected, 1e-5f * expected) << i;
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(sh[k], expected, 1e-5f * expected) << i;
    const float wb = expected_weight(file.ddgi_volumes()[1].desc(), p);
    both += wb > 0.f && wb < 1.f;
  }
  EXPECT_GT(both, 100);  // many points in the fine volume's fade band, where the blend mixes
}

}  // namespace
