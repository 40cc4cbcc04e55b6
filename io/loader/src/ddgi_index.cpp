// The DDGI volume index (format 1.4, docs/FORMAT.md "Volume index"): building its words for a
// writer, validating a file's, and finding a point's list. A list may hold more volumes than can
// weigh in at a point (the loop skips them), never fewer, so sampling through it changes no bit.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "gibake/loader.hpp"

namespace gibake::loader {
namespace {

constexpr uint32_t kHeader = GIBAKE_DDGI_INDEX_HEADER_WORDS;
constexpr uint64_t kMaxCells = uint64_t(1) << 24;  // what a reader accepts
constexpr int32_t kMaxDims = 1 << 16;

Error fail(std::string message) { return Error{ErrorCode::BadVolume, std::move(message)}; }

// A volume's region per axis in metres (exact, in double): the probe box grown by one spacing, as
// DdgiVolume::region_contains tests it ((p - grid_min) / spacing within [-1, counts]). An axis of
// one probe is unbounded.
struct Region {
  double lo[3], hi[3];
  bool bounded[3];
};

Region region_of(const gibake_ddgi_volume& d) {
  Region r{};
  for (int a = 0; a < 3; ++a) {
    r.bounded[a] = d.counts[a] > 1 && d.spacing[a] > 0.f;
    r.lo[a] = double(d.grid_min[a]) - double(d.spacing[a]);
    r.hi[a] = double(d.grid_min[a]) + double(d.counts[a]) * double(d.spacing[a]);
  }
  return r;
}

// The union of the regions on every axis; an axis no volume bounds spans their probe positions.
// `edge`: the smallest region edge of any volume on any bounded axis (infinity with none).
void union_extent(const std::vector<Region>& regions, const std::vector<gibake_ddgi_volume>& volumes,
                  double lo[3], double hi[3], double& edge) {
  edge = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -lo[a];
    for (const Region& r : regions) {
      if (!r.bounded[a]) continue;
      lo[a] = std::min(lo[a], r.lo[a]);
      hi[a] = std::max(hi[a], r.hi[a]);
      edge = std::min(edge, r.hi[a] - r.lo[a]);
    }
    if (lo[a] <= hi[a]) continue;
    for (const gibake_ddgi_volume& d : volumes) {
      lo[a] = std::min(lo[a], double(d.grid_min[a]));
      hi[a] = std::max(hi[a], double(d.grid_min[a]));
    }
  }
}

// Cells per axis for cell edge c over [grid_min, hi]; the product (saturating).
uint64_t grid_dims(const float grid_min[3], const double hi[3], float c, int32_t dims[3]) {
  uint64_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    const double n = std::ceil((hi[a] - double(grid_min[a])) / double(c));
    dims[a] = n > double(kMaxDims) ? kMaxDims + 1 : std::max(1, int32_t(n));
    cells = std::min(cells * uint64_t(dims[a]), uint64_t(1) << 40);
  }
  return cells;
}

uint32_t load_word(const uint8_t* words, uint64_t i) {
  uint32_t w;
  std::memcpy(&w, words + i * 4, 4);
  return w;
}

}  // namespace

std::vector<uint32_t> build_ddgi_volume_index(const std::vector<gibake_ddgi_volume>& volumes) {
  if (volumes.size() < 2) return {};
  std::vector<Region> regions;
  for (const gibake_ddgi_volume& d : volumes) regions.push_back(region_of(d));
  double lo[3], hi[3], edge = 0.0;
  union_extent(regions, volumes, lo, hi, edge);
  gibake_ddgi_volume_index h{};
  for (int a = 0; a < 3; ++a) {
    h.grid_min[a] = float(lo[a]);
    if (double(h.grid_min[a]) > lo[a]) h.grid_min[a] = std::nextafter(h.grid_min[a], -INFINITY);
  }
  if (!std::isfinite(edge)) edge = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  float c = edge > 0.0 ? float(edge) : 1.f;
  while (grid_dims(h.grid_min, hi, c, h.dims) > GIBAKE_DDGI_INDEX_MAX_CELLS) c *= 2.f;
  h.cell_size = c;
  h.cell_count = uint32_t(uint64_t(h.dims[0]) * uint64_t(h.dims[1]) * uint64_t(h.dims[2]));
  h.volume_count = uint32_t(volumes.size());
  // meets[a][v][i]: volume v's region, grown by the margin, meets cell column i along axis a.
  const double margin = double(c) / 16.0;
  std::vector<std::vector<std::vector<char>>> meets(3, std::vector<std::vector<char>>(volumes.size()));
  for (int a = 0; a < 3; ++a)
    for (size_t v = 0; v < volumes.size(); ++v) {
      const Region& r = regions[v];
      meets[a][v].resize(size_t(h.dims[a]));
      for (int32_t i = 0; i < h.dims[a]; ++i) {
        const double cell_lo = double(h.grid_min[a]) + double(i) * double(c), cell_hi = cell_lo + double(c);
        meets[a][v][size_t(i)] = !r.bounded[a] || (r.lo[a] - margin <= cell_hi && r.hi[a] + margin >= cell_lo);
      }
    }
  const std::vector<uint32_t> order = ddgi_priority_order(volumes);
  std::vector<uint32_t> offsets{0u}, ids;
  for (int32_t z = 0; z < h.dims[2]; ++z)
    for (int32_t y = 0; y < h.dims[1]; ++y)
      for (int32_t x = 0; x < h.dims[0]; ++x) {
        const size_t before = ids.size();
        for (uint32_t v : order)
          if (meets[0][v][size_t(x)] && meets[1][v][size_t(y)] && meets[2][v][size_t(z)]) ids.push_back(v);
        h.longest = std::max(h.longest, uint32_t(ids.size() - before));
        offsets.push_back(uint32_t(ids.size()));
      }
  h.id_count = uint32_t(ids.size());
  std::vector<uint32_t> words(kHeader);
  std::memcpy(words.data(), &h, sizeof h);
  words.insert(words.end(), offsets.begin(), offsets.end());
  words.insert(words.end(), ids.begin(), ids.end());
  return words;
}

uint32_t DdgiVolumeIndex::word(uint64_t i) const { return i < word_count_ ? load_word(words_, i) : 0u; }

bool DdgiVolumeIndex::cell_of(const Vec3& p, uint32_t& cell) const {
  if (!present()) return false;
  uint32_t at[3];
  for (int a = 0; a < 3; ++a) {
    const float x = (p[size_t(a)] - desc_.grid_min[a]) / desc_.cell_size;
    if (!(x >= 0.f && x < float(desc_.dims[a]))) return false;  // NaN: outside
    at[a] = std::min(uint32_t(x), uint32_t(desc_.dims[a] - 1));
  }
  cell = at[0] + uint32_t(desc_.dims[0]) * (at[1] + uint32_t(desc_.dims[1]) * at[2]);
  return true;
}

uint32_t DdgiVolumeIndex::list_size(uint32_t cell) const {
  if (cell >= desc_.cell_count) return 0;
  return word(kHeader + uint64_t(cell) + 1) - word(kHeader + uint64_t(cell));
}

uint32_t DdgiVolumeIndex::list_id(uint32_t cell, uint32_t k) const {
  if (cell >= desc_.cell_count) return 0;
  return word(kHeader + uint64_t(desc_.cell_count) + 1 + uint64_t(word(kHeader + uint64_t(cell))) + k);
}

// Validates the header, then the offsets (from 0, never decreasing, ending at id_count), then every
// id (a volume, lists in priority order): afterwards every list read stays inside the section.
Error BakeFile::build_ddgi_index() {
  int32_t found = -1;
  for (uint32_t i = 0; i < sections_.size(); ++i) {
    if (sections_[i].type != GIBAKE_SECTION_DDGI_VOLUME_INDEX) continue;
    if (found >= 0)
      return Error{ErrorCode::DuplicateSection, "section " + std::to_string(i) + " (ddgi_volume_index): a second index"};
    found = int32_t(i);
  }
  if (found < 0) return {};
  const gibake_section_entry& s = sections_[size_t(found)];
  const std::string label = "section " + std::to_string(found) + " (ddgi_volume_index): ";
  if (s.count < kHeader) return fail(label + std::to_string(s.count) + " words, shorter than its 16-word header");
  gibake_ddgi_volume_index d;
  std::memcpy(&d, data_ + s.offset, sizeof d);
  uint64_t cells = 1;
  for (int a = 0; a < 3; ++a) {
    if (d.dims[a] < 1 || d.dims[a] > kMaxDims) return fail(label + "cell count on axis " + std::to_string(a) + " out of range");
    cells *= uint64_t(d.dims[a]);
  }
  if (cells > kMaxCells || cells != d.cell_count)
    return fail(label + "cell_count " + std::to_string(d.cell_count) + " != product of dims " + std::to_string(cells) +
                " (at most 2^24)");
  bool finite = std::isfinite(d.cell_size) && d.cell_size > 0.f;
  for (int a = 0; a < 3; ++a)
    finite = finite && std::isfinite(d.grid_min[a]) && std::isfinite(d.grid_min[a] + float(d.dims[a]) * d.cell_size);
  if (!finite) return fail(label + "non-finite grid or cell size not > 0");
  if (d.volume_count != volumes_.size())
    return fail(label + "volume_count " + std::to_string(d.volume_count) + " != the file's " +
                std::to_string(volumes_.size()) + " DDGI volumes");
  if (d.flags != 0 || d.reserved[0] || d.reserved[1] || d.reserved[2] || d.reserved[3])
    return fail(label + "flags or reserved words not 0");
  if (s.count != uint64_t(kHeader) + cells + 1 + d.id_count)
    return fail(label + std::to_string(s.count) + " words, the header needs " +
                std::to_string(uint64_t(kHeader) + cells + 1 + d.id_count));
  const uint8_t* words = data_ + s.offset;
  uint32_t prev = load_word(words, kHeader), longest = 0;
  if (prev != 0) return fail(label + "the first offset is not 0");
  for (uint64_t c = 1; c <= cells; ++c) {
    const uint32_t o = load_word(words, kHeader + c);
    if (o < prev || o > d.id_count)
      return fail(label + "offset of cell " + std::to_string(c) + " decreases or passes id_count");
    longest = std::max(longest, o - prev);
    prev = o;
  }
  if (prev != d.id_count) return fail(label + "the last offset is not id_count");
  if (longest != d.longest) return fail(label + "longest " + std::to_string(d.longest) + " != the longest list " +
                                        std::to_string(longest));
  std::vector<uint32_t> rank(volumes_.size());
  for (uint32_t r = 0; r < ddgi_order_.size(); ++r) rank[ddgi_order_[r]] = r;
  const uint64_t first_id = kHeader + cells + 1;
  for (uint64_t c = 0; c < cells; ++c) {
    const uint32_t begin = load_word(words, kHeader + c), end = load_word(words, kHeader + c + 1);
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t id = load_word(words, first_id + k);
      if (id >= d.volume_count)
        return fail(label + "cell " + std::to_string(c) + " lists volume " + std::to_string(id) + " of " +
                    std::to_string(d.volume_count));
      if (k > begin && rank[id] <= rank[load_word(words, first_id + k - 1)])
        return fail(label + "cell " + std::to_string(c) + ": volumes not in priority order");
    }
  }
  index_.desc_ = d;
  index_.words_ = words;
  index_.word_count_ = s.count;
  index_.section_ = uint32_t(found);
  return {};
}

}  // namespace gibake::loader
