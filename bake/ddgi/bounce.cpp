#include "bake/ddgi/bounce.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

#include "bake/run/probe_loop.h"
#include "io/results/ddgi_result.h"
#include "kernels/integrate.h"
#include "kernels/sh.h"
#include "kernels/shade.h"
#include "io/timer.h"

namespace gibake {
using kernels::float3;

namespace {
constexpr int kIrrTile = kIrradianceTexels * kIrradianceTexels * 3;

// The probe weights of every bouncing hit, flattened probe after probe (hit i of probe p at
// first[p] + i). (Not in grid-cell order for depth-tile locality: the sort costs more than the
// cache misses it saves.)
void compute_weights(const BounceInputs& in, tbb::task_arena& arena, const std::vector<size_t>& first,
                     std::vector<kernels::ProbeWeights>& weights) {
  const std::vector<std::vector<BounceHit>>& hits = *in.hits;
  weights.resize(first.back());
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, hits.size(), 2), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t p = r.begin(); p != r.end(); ++p) {
        const float3 origin = kernels::load3(in.positions + p * 3);
        for (size_t i = 0; i < hits[p].size(); ++i) {
          const BounceHit& h = hits[p][i];
          const float3 hit = origin + kernels::load3(h.dir_t) * h.dir_t[3];
          weights[first[p] + i] = kernels::ddgi_probe_weights(in.volume, hit, kernels::load3(h.normal));
        }
      }
    });
  });
}

}  // namespace

void run_bounce_passes(const BounceInputs& in, tbb::task_arena& arena, const Context& ctx, std::vector<float>& sh,
                       std::vector<float>& irradiance, BounceTimes& times) {
  const std::vector<float>& sh0 = *in.sh0;
  const std::vector<std::vector<BounceHit>>& bounce_hits = *in.hits;
  const int32_t probe_count = static_cast<int32_t>(bounce_hits.size());
  const int coefs = kernels::sh_coefficient_count(in.sh_order);
  std::vector<int32_t> all_probes(probe_count);
  for (int32_t i = 0; i < probe_count; ++i) all_probes[i] = i;

  auto t0 = Clock::now();
  std::vector<float> prev_sh = sh0, cur_sh(sh0.size(), 0.f);
  // The probe weights of each bouncing hit (trilinear, back-face, Chebyshev visibility) depend on
  // positions, states and depth moments only: computed once, reused by every pass.
  std::vector<size_t> first(size_t(probe_count) + 1, 0);
  for (int32_t p = 0; p < probe_count; ++p) first[p + 1] = first[p] + bounce_hits[p].size();
  std::vector<kernels::ProbeWeights> weights;
  if (in.bounces > 0) compute_weights(in, arena, first, weights);
  tbb::enumerable_thread_specific<std::vector<kernels::RaySample>> scratch;
  for (int pass = 1; pass <= in.bounces; ++pass) {
    const bool last = pass == in.bounces;
    for_probes_reporting(arena, all_probes, ctx, "bounce " + std::to_string(pass), [&](int32_t p) {
      float* out = &cur_sh[size_t(p) * coefs * 3];
      if (in.volume.inactive && in.volume.inactive[p]) {
        std::fill(out, out + coefs * 3, 0.f);
        return;
      }
      const float* base = &sh0[size_t(p) * coefs * 3];
      const std::vector<BounceHit>& b = bounce_hits[p];
      const kernels::ProbeWeights* pw = weights.data() + first[p];
      std::vector<kernels::RaySample>& rsv = scratch.local();
      rsv.resize(b.size());
      kernels::RaySample* rs = rsv.data();
      for (size_t i = 0; i < b.size(); ++i) {
        const BounceHit& rec = b[i];
        for (int a = 0; a < 4; ++a) rs[i].dir_depth[a] = rec.dir_t[a];
        const float3 e =
            kernels::ddgi_irradiance_from_weights(prev_sh.data(), in.sh_order, pw[i], kernels::load3(rec.normal));
        kernels::store3(rs[i].radiance, kernels::shade_indirect(kernels::load3(rec.albedo), e, in.energy_conservation));
        rs[i].radiance[3] = 0.f;
      }
      float add_sh[kernels::kMaxShCoefficients * 3];
      float add_irr[kIrrTile];
      kernels::integrate_radiance(in.texel_dirs, kIrradianceTexels, rs, static_cast<int>(b.size()), in.sh_order, add_sh,
                                  last ? add_irr : nullptr);
      const float scale = in.probe_rays[p] == 0 ? 0.f : float(b.size()) / float(in.probe_rays[p]);
      for (int k = 0; k < coefs * 3; ++k) out[k] = base[k] + add_sh[k] * scale;
      if (last) {
        float* irr = &irradiance[size_t(p) * kIrrTile];
        for (int k = 0; k < kIrrTile; ++k) irr[k] += add_irr[k] * scale;
      }
    });
    prev_sh.swap(cur_sh);
    if (pass == 1) {
      times.stage_seconds.emplace_back("bounce1", seconds_since(t0));
      t0 = Clock::now();
    }
  }
  if (in.bounces > 1) times.stage_seconds.emplace_back("bounces2+", seconds_since(t0));
  sh = std::move(prev_sh);
}

}  // namespace gibake
