// BakeFile::sample_ddgi, the blend of several DDGI volumes (docs/FORMAT.md "Several volumes"):
// expected values computed here from the rule as written (a volume's region is its probe box grown
// by half a spacing, its weight per axis the distance to the region's face in spacings, clamped to
// 1), not through the loader's blend_weight.
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

// The rule's weight, from the description: min over the two faces of the region of the distance in
// metres, divided by the spacing, clamped to [0, 1]; the product over the axes.
float expected_weight(const gibake_ddgi_volume& d, const Vec3& p) {
  double w = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double lo = double(d.grid_min[a]) - 0.5 * d.spacing[a], hi = double(d.grid_max[a]) + 0.5 * d.spacing[a];
    const double in = std::min(double(p[a]) - lo, hi - double(p[a])) / d.spacing[a];
    w *= std::clamp(in, 0.0, 1.0);
  }
  return float(w);
}

Vec3 unit(float x, float y, float z) {
  const float l = std::sqrt(x * x + y * y + z * z);
  return {x / l, y / l, z / l};
}

bool same_bits(const Rgb& a, const Rgb& b) { return std::memcmp(a.data(), b.data(), sizeof a) == 0; }

Rgb answer(const loader::DdgiVolume& v, const Vec3& p, const Vec3& n) {
  Rgb e;
  EXPECT_TRUE(v.try_sample_irradiance(p, n, e)) << "no answer at " << p[0] << "," << p[1] << "," << p[2];
  return e;
}

// A coarse volume (region [-1, 9]^3, spacing 2) holding a fine one (probe box [2, 4]^3, spacing 0.5,
// region [1.75, 4.25]^3), the fine one second in the file: priority must put it first.
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
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(2.25f, 3.75f);  // weight 1 in the fine volume
  int compared = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng)}, n = unit(u(rng) - 3.f, 1.f, u(rng) - 3.f);
    ASSERT_FLOAT_EQ(expected_weight(fine().desc(), p), 1.f);
    Rgb fine_e, out;
    if (!fine().try_sample_irradiance(p, n, fine_e)) continue;
    ASSERT_TRUE(file_.sample_ddgi(p, n, out));
    EXPECT_TRUE(same_bits(out, fine_e)) << i;
    EXPECT_FALSE(same_bits(out, coarse().sample_irradiance(p, n))) << i;  // the coarse one differs
    ++compared;
  }
  EXPECT_GT(compared, 200);
}

TEST_F(Nested, OutsideTheFinerVolumeTheCoarseOneAnswersAlone) {
  for (const Vec3& p : {Vec3{0.5f, 0.5f, 0.5f}, Vec3{1.7f, 3.f, 3.f}, Vec3{4.3f, 2.f, 8.9f}, Vec3{-0.9f, 8.f, 1.f},
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
  int checked = 0;
  for (const Vec3& p : {Vec3{2.f, 3.f, 3.f}, Vec3{1.9f, 2.1f, 4.1f}, Vec3{4.2f, 3.3f, 2.6f}, Vec3{3.f, 2.2f, 1.8f},
                        Vec3{3.1f, 4.05f, 3.f}}) {
    const float w = expected_weight(fine().desc(), p);
    ASSERT_GT(w, 0.f);
    ASSERT_LT(w, 1.f);
    ASSERT_FLOAT_EQ(expected_weight(coarse().desc(), p), 1.f);
    for (const Vec3& n : {unit(0, 1, 0), unit(-1, 0.2f, 0.4f), unit(0.1f, -1.f, 0.7f)}) {
      const Rgb f = answer(fine(), p, n), c = answer(coarse(), p, n);
      Rgb out;
      ASSERT_TRUE(file_.sample_ddgi(p, n, out));
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

// Two volumes of equal spacing side by side, their regions overlapping by half a spacing: the
// first in the file comes first; where both are in their fade bands only, the sum is normalised.
TEST(Blend, FadeBandsOnlyAreNormalisedAndTiesKeepFileOrder) {
  DdgiResult a = volume(3, {20.f, 0.f, 0.f}, 1.f, 421), b = volume(3, {22.5f, 0.f, 0.f}, 1.f, 422);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&a, &b}, bytes);
  ASSERT_EQ(file.ddgi_priority(), (std::vector<uint32_t>{0u, 1u}));
  const loader::DdgiVolume &va = file.ddgi_volumes()[0], &vb = file.ddgi_volumes()[1];
  for (const Vec3& p : {Vec3{22.25f, 1.f, 1.f}, Vec3{22.1f, 1.2f, 0.8f}, Vec3{22.4f, 0.f, 2.3f}}) {
    const Vec3 n = unit(0.f, 1.f, 0.3f);
    const float wa = expected_weight(va.desc(), p), wb = expected_weight(vb.desc(), p);
    ASSERT_GT(wa, 0.f);
    ASSERT_GT(wb, 0.f);
    ASSERT_LT(wa + wb * (1.f - wa), 1.f);
    const float ca = wa, cb = wb * (1.f - wa);
    const Rgb ea = answer(va, p, n), eb = answer(vb, p, n);
    Rgb out;
    ASSERT_TRUE(file.sample_ddgi(p, n, out));
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(out[k], (ca * ea[k] + cb * eb[k]) / (ca + cb), 1e-5f * std::max({1.f, ea[k], eb[k]}));
  }
  // Only one of them: its own answer, to the bit, in its fade band too.
  for (const Vec3& p : {Vec3{19.6f, 1.f, 1.f}, Vec3{21.f, 2.4f, -0.4f}, Vec3{24.9f, 1.f, 1.f}}) {
    const Vec3 n = unit(1.f, 0.5f, 0.f);
    const loader::DdgiVolume& only = p[0] < 22.f ? va : vb;
    Rgb out;
    ASSERT_TRUE(file.sample_ddgi(p, n, out));
    EXPECT_TRUE(same_bits(out, only.sample_irradiance(p, n)));
  }
}

// Outside every region: false, and the nearest volume's clamped answer.
TEST(Blend, OutsideEveryVolumeIsFalse) {
  DdgiResult a = volume(3, {0.f, 0.f, 0.f}, 1.f, 431), b = volume(3, {10.f, 0.f, 0.f}, 0.5f, 432);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&a, &b}, bytes);
  const Vec3 n = unit(0, 1, 0);
  for (const Vec3& p : {Vec3{5.f, 1.f, 1.f}, Vec3{-0.6f, 1.f, 1.f}, Vec3{1.f, 1.f, 2.6f}, Vec3{1e4f, 0.f, 0.f},
                        Vec3{11.f, 1.f, 1.3f}}) {
    Rgb out;
    EXPECT_FALSE(file.sample_ddgi(p, n, out)) << p[0] << "," << p[1] << "," << p[2];
    const loader::DdgiVolume& nearest = p[0] < 5.5f ? file.ddgi_volumes()[0] : file.ddgi_volumes()[1];
    EXPECT_TRUE(same_bits(out, nearest.sample_irradiance(p, n)));
  }
  Rgb out;
  EXPECT_TRUE(file.sample_ddgi({-0.49f, 1.f, 1.f}, n, out));  // just inside the region
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
      const float lo = d.grid_min[a] - 0.5f * d.spacing[a], hi = d.grid_max[a] + 0.5f * d.spacing[a];
      p[a] = lo + u(rng) * (hi - lo);
      in = in && p[a] >= lo && p[a] <= hi;
    }
    const Vec3 n = unit(g(rng), g(rng), g(rng));
    Rgb out;
    EXPECT_EQ(file.sample_ddgi(p, n, out), in) << i;
    EXPECT_TRUE(same_bits(out, v.sample_irradiance(p, n))) << i;
    inside += in;
  }
  EXPECT_GT(inside, 300);  // (1 / 1.6)^3 of the points lie inside
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
    std::fill(r.states.begin(), r.states.end(), ProbeState::Active);  // an answer everywhere
  };
  DdgiResult a = volume(4, {0.f, 0.f, 0.f}, 1.f, 451), b = volume(5, {1.3f, 0.7f, 1.1f}, 0.4f, 452);
  constant(a);
  constant(b);
  std::vector<uint8_t> bytes;
  const loader::BakeFile file = open_volumes({&a, &b}, bytes);
  const float expected = 3.14159265f * radiance;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.5f, 3.5f);
  std::normal_distribution<float> g(0.f, 1.f);
  int both = 0;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 p{u(rng), u(rng), u(rng)}, n = unit(g(rng), g(rng), g(rng));
    Rgb out;
    ASSERT_TRUE(file.sample_ddgi(p, n, out));
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(out[k], expected, 1e-5f * expected) << i;
    const float wb = expected_weight(file.ddgi_volumes()[1].desc(), p);
    both += wb > 0.f && wb < 1.f;
  }
  EXPECT_GT(both, 100);  // many points in the fine volume's fade band, where the blend mixes
}

}  // namespace
