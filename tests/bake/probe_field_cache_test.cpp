// Probe field reads shared per key (bake/trace/probe_field_cache.h), against fields made up here:
// a value is the field at its key's own point and normal, whatever read it first and on whichever
// thread; that point lies within a cell's diagonal of every hit with the key; a smooth field is
// read within what its gradient allows over that distance; repeated reads of a patch read the
// field once per key.
#include "bake/trace/probe_field_cache.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <set>
#include <tuple>
#include <vector>

#include "kernels/ray_gen.h"

namespace gibake {
namespace {

using kernels::float3;

// E(p, n) = 1000 + 50 p.x - 30 p.y + 20 p.z + 200 n.y lux: smooth, with known gradients. Counts
// its reads.
struct LinearField : ProbeField {
  float3 irradiance(const float3& p, const float3& n) const override {
    ++reads;
    const float e = 1000.f + 50.f * p.x - 30.f * p.y + 20.f * p.z + 200.f * n.y;
    return float3{e, 0.5f * e, 0.25f * e};
  }
  mutable std::atomic<uint64_t> reads{0};
};

constexpr float kCell = 0.125f;

// Random hits on the surfaces of a room-sized box of walls, floor and a tilted slab.
struct Hit {
  float3 p, n;
};
std::vector<Hit> hits(uint64_t count) {
  std::vector<Hit> out;
  for (uint64_t i = 0; i < count; ++i) {
    const float u = kernels::rng_uniform(i, 0), v = kernels::rng_uniform(i, 1), w = kernels::rng_uniform(i, 2);
    switch (i % 4) {
      case 0:
        out.push_back({float3{6.f * u - 3.f, 0.f, 4.f * v - 2.f}, float3{0.f, 1.f, 0.f}});
        break;
      case 1:
        out.push_back({float3{-3.f, 3.f * u, 4.f * v - 2.f}, float3{1.f, 0.f, 0.f}});
        break;
      case 2:
        out.push_back({float3{6.f * u - 3.f, 3.f * v, 2.f}, float3{0.f, 0.f, -1.f}});
        break;
      default: {
        const float3 n = kernels::normalize(float3{0.3f, 1.f, 0.2f + 0.1f * w});
        const float3 p{4.f * u - 2.f, 1.f, 3.f * v - 1.5f};
        out.push_back({p - n * (kernels::dot(p, n) - 1.f), n});  // on the plane dot(p, n) = 1
      }
    }
  }
  return out;
}

TEST(ProbeFieldCache, AValueIsTheFieldAtItsKeysOwnPoint) {
  LinearField field;
  const CachedProbeField cached(field, kCell, 16);
  EXPECT_FALSE(cached.used());
  for (const Hit& h : hits(2000)) {
    const float3 e = cached.irradiance(h.p, h.n);
    float3 at, normal;
    cached.read_at(cached.key_of(h.p, h.n), at, normal);
    const float3 direct = field.irradiance(at, normal);
    EXPECT_EQ(e.x, direct.x);
    EXPECT_EQ(e.y, direct.y);
    EXPECT_EQ(e.z, direct.z);
  }
  EXPECT_TRUE(cached.used());
}

TEST(ProbeFieldCache, TheReadPointLiesNearEveryHitOfItsKey) {
  LinearField field;
  const CachedProbeField cached(field, kCell, 16);
  for (const Hit& h : hits(20000)) {
    float3 at, normal;
    cached.read_at(cached.key_of(h.p, h.n), at, normal);
    // The cube's centre moved along the normal onto the key's plane: within the cube's diagonal.
    EXPECT_LE(kernels::length(at - h.p), std::sqrt(3.f) * kCell);
    // Within an octahedral bin of 32 x 32: a few degrees, never ten.
    EXPECT_GT(kernels::dot(normal, h.n), std::cos(10.f * 3.14159265f / 180.f));
    // On the hit's plane to an eighth of a cell (plus the normal's tilt over that distance).
    EXPECT_LE(std::fabs(kernels::dot(at - h.p, h.n)), kCell / 8.f + 0.25f * kCell);
  }
}

TEST(ProbeFieldCache, ASmoothFieldIsReadWithinItsGradientOverACell) {
  LinearField field;
  const CachedProbeField cached(field, kCell, 16);
  // |grad_p E| = sqrt(50^2 + 30^2 + 20^2) lux/m over sqrt(3) cells, 200 lux a radian over 10 degrees.
  const float bound = std::sqrt(50.f * 50.f + 30.f * 30.f + 20.f * 20.f) * std::sqrt(3.f) * kCell + 200.f * 0.175f;
  double worst = 0.0;
  for (const Hit& h : hits(20000)) {
    const float exact = field.irradiance(h.p, h.n).x;
    const float read = cached.irradiance(h.p, h.n).x;
    worst = std::max(worst, double(std::fabs(read - exact)));
  }
  EXPECT_LE(worst, bound);
  EXPECT_GT(worst, 0.0);  // the reads are shared: not the field at the hit itself
}

TEST(ProbeFieldCache, HitsOnOnePatchReadTheFieldOncePerKey) {
  LinearField field;
  const CachedProbeField cached(field, kCell, 16);
  // Hits on one 0.5 m square of floor, each read many times over.
  std::set<std::tuple<int32_t, int32_t, int32_t, int32_t, int32_t>> keys;
  for (int round = 0; round < 8; ++round)
    for (uint64_t i = 0; i < 4000; ++i) {
      const float3 p{0.5f * kernels::rng_uniform(i, 0), 0.f, 0.5f * kernels::rng_uniform(i, 1)};
      const float3 n{0.f, 1.f, 0.f};
      cached.irradiance(p, n);
      const CachedProbeField::Key k = cached.key_of(p, n);
      keys.insert({k.cell[0], k.cell[1], k.cell[2], k.plane, k.normal});
    }
  EXPECT_LE(keys.size(), 32u);  // 4 x 4 cells, at most two plane steps each
  EXPECT_EQ(field.reads.load(), keys.size());
}

TEST(ProbeFieldCache, ReadsDoNotDependOnTheThreadOrTheOrder) {
  LinearField field;
  const std::vector<Hit> all = hits(50000);
  std::vector<float3> once(all.size()), threaded(all.size());
  {
    const CachedProbeField cached(field, kCell, 16);
    for (size_t i = all.size(); i-- > 0;) once[i] = cached.irradiance(all[i].p, all[i].n);  // backwards
  }
  {
    const CachedProbeField cached(field, kCell, 16);
    tbb::task_arena arena(4);
    arena.execute([&] {
      tbb::parallel_for(size_t(0), all.size(), [&](size_t i) { threaded[i] = cached.irradiance(all[i].p, all[i].n); });
    });
  }
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(once[i].x, threaded[i].x) << i;
    EXPECT_EQ(once[i].z, threaded[i].z) << i;
  }
}

TEST(ProbeFieldCache, TheTablesStayWithinTheirMemoryWhateverTheThreads) {
  EXPECT_EQ(CachedProbeField::table_bits_for(2), 20);
  for (uint32_t threads : {1u, 2u, 8u, 16u, 64u, 256u}) {
    const int bits = CachedProbeField::table_bits_for(threads);
    EXPECT_GE(bits, 16);
    if (bits > 16) {
      EXPECT_LE(threads * CachedProbeField::table_bytes(bits), uint64_t(256) << 20) << threads;
    }
  }
}

}  // namespace
}  // namespace gibake
