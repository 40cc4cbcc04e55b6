#include "io/bakefile/sparse_volume.h"

#include <algorithm>
#include <array>
#include <cstring>

#include "gibake/format.h"

namespace gibake {
namespace {

// Column and row of probe `p`'s tile in `r`'s grid layout (DdgiResult's atlas comment).
std::array<size_t, 2> grid_tile(const DdgiResult& r, uint32_t p) {
  const DdgiVolumeDesc& d = r.desc;
  const size_t X = size_t(d.counts[0]), Y = size_t(d.counts[1]);
  const size_t k = r.atlas_planes_per_row > 0 ? size_t(r.atlas_planes_per_row) : Y;
  const size_t x = p % X, y = (p / X) % Y, z = p / (X * Y);
  return {x + X * (y % k), z + size_t(d.counts[2]) * (y / k)};
}

// Copies every stored probe's bordered tile (`side` texels, `channels` floats each) from the grid
// layout of `from` (`from_width` texels wide) to its slot's place in `to`.
void copy_tiles(const DdgiResult& r, const std::vector<uint32_t>& slots, uint32_t tiles_per_row, size_t side,
                size_t channels, const std::vector<float>& from, size_t from_width, std::vector<float>& to,
                size_t to_width) {
  const size_t row_floats = side * channels;
  for (uint32_t p = 0; p < slots.size(); ++p) {
    if (slots[p] == GIBAKE_PROBE_SLOT_NONE) continue;
    const std::array<size_t, 2> src = grid_tile(r, p);
    const size_t dst_x = size_t(slots[p] % tiles_per_row) * side, dst_y = size_t(slots[p] / tiles_per_row) * side;
    for (size_t y = 0; y < side; ++y)
      std::memcpy(to.data() + ((dst_y + y) * to_width + dst_x) * channels,
                  from.data() + ((src[1] * side + y) * from_width + src[0] * side) * channels,
                  row_floats * sizeof(float));
  }
}

// Per-probe values of the stored probes, `per` values a probe, in slot order.
template <class T>
std::vector<T> stored_values(const std::vector<T>& all, const std::vector<uint32_t>& slots, size_t per,
                             uint32_t stored) {
  std::vector<T> out;
  if (all.empty()) return out;
  out.reserve(size_t(stored) * per);
  for (size_t p = 0; p < slots.size(); ++p)
    if (slots[p] != GIBAKE_PROBE_SLOT_NONE) out.insert(out.end(), all.begin() + p * per, all.begin() + (p + 1) * per);
  return out;
}

}  // namespace

bool make_sparse_volume(const DdgiResult& r, SparseVolume& out) {
  const size_t probes = size_t(r.desc.probe_count());
  if (r.states.size() != probes) return false;  // no states: every probe is read
  std::vector<uint32_t> slots(probes, GIBAKE_PROBE_SLOT_NONE);
  uint32_t stored = 0;
  for (size_t p = 0; p < probes; ++p)
    if (r.states[p] != ProbeState::Inactive) slots[p] = stored++;
  if (stored == 0) return false;
  const size_t irradiance_side = size_t(kIrradianceTexels) + 2, depth_side = size_t(r.depth_tile) + 2;
  // The grid layout's tiles a row, the same count in either atlas.
  const size_t grid_row =
      !r.irradiance_atlas.empty() ? size_t(r.irradiance_width) / irradiance_side : size_t(r.depth_width) / depth_side;
  const uint32_t per_row = uint32_t(std::max<size_t>(1, std::min<size_t>(stored, grid_row)));
  const uint32_t rows = (stored + per_row - 1) / per_row;
  DdgiResult& s = out.result;
  s = DdgiResult{};
  s.desc = r.desc;
  s.settings_json = r.settings_json;
  s.depth_tile = r.depth_tile;
  const size_t coefficients = size_t(r.desc.sh_coefficients());
  s.sh = stored_values(r.sh, slots, coefficients * 3, stored);
  s.offsets = stored_values(r.offsets, slots, 3, stored);
  s.states = stored_values(r.states, slots, 1, stored);
  s.stats = stored_values(r.stats, slots, 1, stored);
  if (!r.irradiance_atlas.empty()) {
    s.irradiance_width = int(per_row * irradiance_side);
    s.irradiance_height = int(rows * irradiance_side);
    s.irradiance_atlas.assign(size_t(s.irradiance_width) * size_t(s.irradiance_height) * 4, 0.f);
    for (size_t a = 3; a < s.irradiance_atlas.size(); a += 4) s.irradiance_atlas[a] = 1.f;  // A = 1 everywhere
    copy_tiles(r, slots, per_row, irradiance_side, 4, r.irradiance_atlas, size_t(r.irradiance_width),
               s.irradiance_atlas, size_t(s.irradiance_width));
  }
  if (!r.depth_atlas.empty()) {
    s.depth_width = int(per_row * depth_side);
    s.depth_height = int(rows * depth_side);
    s.depth_atlas.assign(size_t(s.depth_width) * size_t(s.depth_height) * 2, 0.f);
    copy_tiles(r, slots, per_row, depth_side, 2, r.depth_atlas, size_t(r.depth_width), s.depth_atlas,
               size_t(s.depth_width));
  }
  out.slots = std::move(slots);
  out.stored = stored;
  out.tiles_per_row = per_row;
  return true;
}

}  // namespace gibake
