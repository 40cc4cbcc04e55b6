// Ended paths' first hits kept (kept_hits.h).
#include "bake/trace/kept_hits.h"

#include <algorithm>
#include <cmath>

#include "gibake/loader.hpp"
#include "kernels/octahedral.h"

namespace gibake {

namespace {

using kernels::float3;

uint16_t unorm16(float x) { return uint16_t(std::lround(std::clamp(x * 0.5f + 0.5f, 0.f, 1.f) * 65535.f)); }
float from_unorm16(uint16_t q) { return float(q) / 65535.f * 2.f - 1.f; }

EndedPathHits::Hit packed_hit(const EndedLight& e, uint8_t half) {
  EndedPathHits::Hit h;
  h.p[0] = e.p.x;
  h.p[1] = e.p.y;
  h.p[2] = e.p.z;
  h.weight[0] = loader::float_to_half(e.weight.x);
  h.weight[1] = loader::float_to_half(e.weight.y);
  h.weight[2] = loader::float_to_half(e.weight.z);
  float u = 0.f, v = 0.f;
  kernels::encode_oct(e.n, u, v);
  h.normal[0] = unorm16(u);
  h.normal[1] = unorm16(v);
  h.half = half;
  return h;
}

}  // namespace

float3 kept_hit_light(const EndedPathHits::Hit& h, const ProbeField& field) {
  const float3 p{h.p[0], h.p[1], h.p[2]};
  const float3 n = kernels::normalize(kernels::decode_oct(from_unorm16(h.normal[0]), from_unorm16(h.normal[1])));
  const float3 w{loader::half_to_float(h.weight[0]), loader::half_to_float(h.weight[1]),
                 loader::half_to_float(h.weight[2])};
  return w * field.irradiance(p, n) * (1.f / kernels::kPi);
}

void keep_ended_paths(const std::vector<EndedLight>& ended, const std::vector<uint8_t>& halves,
                      const uint32_t half_count[2], EndedPathHits::Point& out) {
  out = EndedPathHits::Point{};
  out.rays = uint32_t(ended.size());
  out.half_count[0] = half_count[0];
  out.half_count[1] = half_count[1];
  size_t at_hit = 0;
  for (const EndedLight& e : ended) at_hit += e.at_hit ? 1 : 0;
  out.hits.reserve(at_hit);
  for (size_t r = 0; r < ended.size(); ++r) {
    const EndedLight& e = ended[r];
    const float3 base = e.has_after ? e.base + e.after : e.base;
    out.base += base;
    out.base_half_lum[halves[r]] += luminance(base);
    if (e.at_hit) out.hits.push_back(packed_hit(e, halves[r]));
  }
}

}  // namespace gibake
