#include "bake/ddgi/probe_fit.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace gibake {

const char* slab_reason_text(SlabReason r) {
  switch (r) {
    case SlabReason::Solid: return "inside geometry or closed space";
    case SlabReason::BelowFloor: return "below the lowest floor";
    case SlabReason::Outside: return "outside the scene's enclosure";
    default: return "kept";
  }
}

namespace {

constexpr float kKeepVoxels = 1.5f;

enum Kind : uint8_t { kSkip = 0, kSolid, kBelow, kOutside, kUseful };

// First and last surface voxel along each line of the grid (-1 when none), per axis.
struct SurfaceSpans {
  std::vector<int32_t> first[3], last[3];
  std::array<int32_t, 3> d{};
  size_t line(int axis, int32_t x, int32_t y, int32_t z) const {
    if (axis == 0) return size_t(y) + size_t(d[1]) * size_t(z);
    if (axis == 1) return size_t(x) + size_t(d[0]) * size_t(z);
    return size_t(x) + size_t(d[0]) * size_t(y);
  }
  explicit SurfaceSpans(const VoxelGrid& v) : d(v.dims) {
    const size_t n[3] = {size_t(d[1]) * d[2], size_t(d[0]) * d[2], size_t(d[0]) * d[1]};
    for (int a = 0; a < 3; ++a) first[a].assign(n[a], -1), last[a].assign(n[a], -1);
    for (int32_t z = 0; z < d[2]; ++z)
      for (int32_t y = 0; y < d[1]; ++y)
        for (int32_t x = 0; x < d[0]; ++x) {
          if (v.space[size_t(v.linear(x, y, z))] != uint8_t(VoxelSpace::Surface)) continue;
          const int32_t c[3] = {x, y, z};
          for (int a = 0; a < 3; ++a) {
            const size_t l = line(a, x, y, z);
            if (first[a][l] < 0) first[a][l] = c[a];
            last[a][l] = c[a];
          }
        }
  }
  // Strictly between two surface voxels along `axis`.
  bool between(int a, int32_t x, int32_t y, int32_t z, int32_t c) const {
    const size_t l = line(a, x, y, z);
    return first[a][l] >= 0 && first[a][l] < c && c < last[a][l];
  }
};

// The voxel range [v0, v1) whose centres lie in [lo, hi] on each axis.
void box_range(const VoxelGrid& v, const std::array<float, 3>& lo, const std::array<float, 3>& hi,
               std::array<int32_t, 3>& v0, std::array<int32_t, 3>& v1) {
  for (int a = 0; a < 3; ++a) {
    const float f0 = (lo[a] - v.origin[a]) / v.voxel_size - 0.5f, f1 = (hi[a] - v.origin[a]) / v.voxel_size - 0.5f;
    v0[a] = std::clamp(int32_t(std::ceil(f0)), 0, v.dims[a]);
    v1[a] = std::clamp(int32_t(std::floor(f1)) + 1, v0[a], v.dims[a]);
  }
}

// What each voxel of [v0, v1) is (kSkip outside it); kOutside until the caller knows whether the
// scene encloses space. `open`/`enclosed`: open voxels above the lowest floor, and of them those
// above a surface and between surfaces along x and along z.
std::vector<uint8_t> classify(const VoxelGrid& v, const std::array<int32_t, 3>& v0, const std::array<int32_t, 3>& v1,
                              uint64_t& open, uint64_t& enclosed) {
  const SurfaceSpans spans(v);
  std::vector<uint8_t> kind(v.space.size(), kSkip);
  open = enclosed = 0;
  for (int32_t z = v0[2]; z < v1[2]; ++z)
    for (int32_t y = v0[1]; y < v1[1]; ++y)
      for (int32_t x = v0[0]; x < v1[0]; ++x) {
        const size_t i = size_t(v.linear(x, y, z));
        const int32_t lowest = spans.first[1][spans.line(1, x, y, z)];
        if (v.space[i] != uint8_t(VoxelSpace::Exterior)) {
          kind[i] = kSolid;
        } else if (lowest > y) {  // a surface above, none below
          kind[i] = kBelow;
        } else {
          const bool inside =
              lowest >= 0 && lowest < y && spans.between(0, x, y, z, x) && spans.between(2, x, y, z, z);
          kind[i] = inside ? kUseful : kOutside;
          ++open;
          enclosed += inside;
        }
      }
  return kind;
}

// What most of the voxels of [s0, s1) are.
SlabReason slab_reason(const VoxelGrid& v, const std::vector<uint8_t>& kind, const std::array<int32_t, 3>& s0,
                       const std::array<int32_t, 3>& s1) {
  uint64_t solid = 0, below = 0, outside = 0;
  for (int32_t z = s0[2]; z < s1[2]; ++z)
    for (int32_t y = s0[1]; y < s1[1]; ++y)
      for (int32_t x = s0[0]; x < s1[0]; ++x) {
        const uint8_t k = kind[size_t(v.linear(x, y, z))];
        solid += k == kSolid;
        below += k == kBelow;
        outside += k == kOutside;
      }
  return solid >= below && solid >= outside ? SlabReason::Solid
         : below >= outside                 ? SlabReason::BelowFloor
                                            : SlabReason::Outside;
}

// Whether the outermost voxel slab of [v0, v1) on `side` holds open space that continues into
// the box (the voxel inwards open too: not the space outside a wall the slab's voxels straddle)
// and surface voxels, each at least kOpenShare of the slab (a notch where two walls meet is not an
// open side).
constexpr double kOpenShare = 0.01;
bool open_side(const VoxelGrid& v, const std::array<int32_t, 3>& v0, const std::array<int32_t, 3>& v1, int side) {
  const int a = side / 2;
  if (v1[a] - v0[a] < 2) return false;
  std::array<int32_t, 3> s0 = v0, s1 = v1;
  if (side % 2 == 0) s1[a] = v0[a] + 1;
  else s0[a] = v1[a] - 1;
  const int32_t inward = side % 2 == 0 ? 1 : -1;
  const uint8_t kOpen = uint8_t(VoxelSpace::Exterior);
  uint64_t open = 0, surface = 0, all = 0;
  for (int32_t z = s0[2]; z < s1[2]; ++z)
    for (int32_t y = s0[1]; y < s1[1]; ++y)
      for (int32_t x = s0[0]; x < s1[0]; ++x) {
        const uint8_t k = v.space[size_t(v.linear(x, y, z))];
        std::array<int32_t, 3> in{x, y, z};
        in[a] += inward;
        open += k == kOpen && v.space[size_t(v.linear(in[0], in[1], in[2]))] == kOpen;
        surface += k == uint8_t(VoxelSpace::Surface);
        ++all;
      }
  return open > 0 && double(open) >= kOpenShare * double(all) && double(surface) >= kOpenShare * double(all);
}

}  // namespace

BoxFit fit_probe_box(const VoxelGrid& v, const std::array<float, 3>& lo, const std::array<float, 3>& hi) {
  BoxFit fit;
  fit.lo = lo;
  fit.hi = hi;
  if (v.empty() || !(v.voxel_size > 0.f) || v.space.size() != size_t(v.dims[0]) * v.dims[1] * v.dims[2]) return fit;
  std::array<int32_t, 3> v0{}, v1{};
  box_range(v, lo, hi, v0, v1);
  uint64_t open = 0, enclosed = 0;
  std::vector<uint8_t> kind = classify(v, v0, v1, open, enclosed);
  fit.enclosed = 2 * enclosed >= open && enclosed > 0;
  std::array<int32_t, 3> u0 = v1, u1 = v0;  // bounds of the useful voxels
  for (int32_t z = v0[2]; z < v1[2]; ++z)
    for (int32_t y = v0[1]; y < v1[1]; ++y)
      for (int32_t x = v0[0]; x < v1[0]; ++x) {
        uint8_t& k = kind[size_t(v.linear(x, y, z))];
        if (k == kOutside && !fit.enclosed) k = kUseful;
        fit.useful += k == kUseful;
        fit.solid += k == kSolid;
        fit.below_floor += k == kBelow;
        fit.outside += k == kOutside;
        if (k != kUseful) continue;
        const int32_t c[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) u0[a] = std::min(u0[a], c[a]), u1[a] = std::max(u1[a], c[a] + 1);
      }
  for (int side = 0; side < 6; ++side) fit.open[side] = open_side(v, v0, v1, side);
  if (fit.useful == 0) return fit;
  for (int a = 0; a < 3; ++a) {
    // The useful voxels grown by one: the surfaces that bound them (a floor, a wall) lie in the
    // voxels just outside, and the box must hold them, so that the grid's cell box does.
    fit.lo[a] = std::max(lo[a], v.origin[a] + float(u0[a] - 1) * v.voxel_size);
    fit.hi[a] = std::min(hi[a], v.origin[a] + float(u1[a] + 1) * v.voxel_size);
    // A side that would lose only the wall the box already ends at (its surface voxel) stays.
    const float slack = kKeepVoxels * v.voxel_size;
    if (fit.lo[a] - lo[a] <= slack) fit.lo[a] = lo[a];
    if (hi[a] - fit.hi[a] <= slack) fit.hi[a] = hi[a];
    fit.dropped[2 * a] = fit.lo[a] - lo[a];
    fit.dropped[2 * a + 1] = hi[a] - fit.hi[a];
    fit.fitted = fit.fitted || fit.dropped[2 * a] > 0.f || fit.dropped[2 * a + 1] > 0.f;
    if (fit.dropped[2 * a] > 0.f) fit.open[2 * a] = false;
    if (fit.dropped[2 * a + 1] > 0.f) fit.open[2 * a + 1] = false;
  }
  for (int side = 0; side < 6; ++side) {  // why each side went
    if (!(fit.dropped[side] > 0.f)) continue;
    const int a = side / 2;
    std::array<int32_t, 3> s0 = v0, s1 = v1;
    if (side % 2 == 0) s1[a] = u0[a];
    else s0[a] = u1[a];
    fit.why[side] = slab_reason(v, kind, s0, s1);
  }
  return fit;
}

}  // namespace gibake
