// The DDGI volume index (format 1.4, docs/FORMAT.md "Volume index"): written only with two or more
// volumes; BakeFile::sample_ddgi through it gives the loop's answer to the bit; every list is the
// rule's (recomputed here from the rule as written, in double, with its own priority sort) and holds
// every volume whose region holds a point of the cell; a hostile index is refused (BadVolume,
// DuplicateSection), never read outside the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>

#include "gibake/loader.hpp"
#include "multi_volume.h"
#include "synthetic.h"
#include "test_util.h"

namespace {

using namespace gibake;
using loader::Rgb;
using loader::Vec3;

DdgiResult volume(std::array<int, 3> n, Vec3 grid_min, Vec3 spacing, uint32_t seed) {
  DdgiResult r = test::make_ddgi(n[0], n[1], n[2], 2, seed);
  for (int a = 0; a < 3; ++a) {
    r.desc.grid_min[a] = grid_min[a];
    r.desc.spacing[a] = n[a] > 1 ? spacing[a] : 0.f;
    r.desc.grid_max[a] = grid_min[a] + r.desc.spacing[a] * float(n[a] - 1);
  }
  for (size_t p = 0; p < r.states.size(); ++p) r.states[p] = p % 7 == 3 ? ProbeState::Inactive : ProbeState::Active;
  return r;
}

// Written the way a bake writes them (BakeOutputs::ddgi and ddgi_more).
std::vector<uint8_t> bake_bytes(const std::vector<DdgiResult>& volumes) {
  BakeOutputs outputs;
  outputs.ddgi = &volumes[0];
  for (size_t v = 1; v < volumes.size(); ++v) outputs.ddgi_more.push_back(&volumes[v]);
  BakeFileOptions o;
  o.atlas = FloatPrecision::Full;
  std::vector<uint8_t> bytes;
  const Status st = build_bake_file(outputs, o, bytes);
  EXPECT_TRUE(st.is_ok()) << st.message();
  return bytes;
}

// Scenes: a coarse grid with finer volumes nested, overlapping and beside it; a ground grid of one
// Y layer (unbounded along Y) under many small fine volumes; two volumes of one probe along X.
std::vector<DdgiResult> nested() {
  return {volume({6, 6, 6}, {0.f, 0.f, 0.f}, {2.f, 2.f, 2.f}, 601), volume({3, 4, 3}, {10.5f, 1.f, 1.f}, {2.f, 2.f, 2.f}, 602),
          volume({5, 5, 5}, {2.f, 2.f, 2.f}, {0.5f, 0.5f, 0.5f}, 603),
          volume({4, 3, 4}, {2.6f, 2.4f, 2.5f}, {0.3f, 0.4f, 0.3f}, 604)};
}

std::vector<DdgiResult> many_fine() {
  std::vector<DdgiResult> v{volume({8, 1, 8}, {-10.f, 0.5f, -10.f}, {3.f, 0.f, 3.f}, 700)};
  std::mt19937 rng(71);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (uint32_t k = 0; k < 24; ++k) {
    const float s = 0.25f + 0.5f * u(rng);
    v.push_back(volume({3 + int(k % 3), 2 + int(k % 4), 3}, {-9.f + 18.f * u(rng), 3.f * u(rng), -9.f + 18.f * u(rng)},
                       {s, s * 0.8f, s}, 701 + k));
  }
  return v;
}

std::vector<DdgiResult> one_probe_axes() {
  return {volume({1, 4, 4}, {1.f, 0.f, 0.f}, {0.f, 1.f, 1.f}, 801), volume({1, 3, 3}, {2.f, 1.f, 1.f}, {0.f, 0.5f, 0.5f}, 802),
          volume({3, 3, 3}, {0.f, 0.5f, 0.5f}, {0.7f, 0.7f, 0.7f}, 803)};
}

bool same_bits(const Rgb& a, const Rgb& b) { return std::memcmp(a.data(), b.data(), sizeof a) == 0; }

// The rule as written, in double: regions, their union, the cell edge, the lists.
struct Rule {
  double lo[3], hi[3];
  bool bounded[3];
};

Rule region(const gibake_ddgi_volume& d) {
  Rule r{};
  for (int a = 0; a < 3; ++a) {
    r.bounded[a] = d.counts[a] > 1;
    r.lo[a] = double(d.grid_min[a]) - double(d.spacing[a]);
    r.hi[a] = double(d.grid_min[a]) + double(d.spacing[a]) * double(d.counts[a]);
  }
  return r;
}

std::vector<uint32_t> priority(const loader::BakeFile& file) {
  std::vector<std::pair<double, uint32_t>> keyed;
  for (uint32_t i = 0; i < file.ddgi_volumes().size(); ++i) {
    const gibake_ddgi_volume& d = file.ddgi_volumes()[i].desc();
    double s = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a)
      if (d.counts[a] > 1) s = std::min(s, double(d.spacing[a]));
    keyed.push_back({s, i});
  }
  std::sort(keyed.begin(), keyed.end());  // equal spacings: the smaller file index first
  std::vector<uint32_t> order;
  for (const auto& k : keyed) order.push_back(k.second);
  return order;
}

std::vector<uint32_t> list(const loader::DdgiVolumeIndex& index, uint32_t cell) {
  std::vector<uint32_t> ids;
  for (uint32_t k = 0; k < index.list_size(cell); ++k) ids.push_back(index.list_id(cell, k));
  return ids;
}

// Every list equals the rule's; the grid is the union of the regions, its cell edge the smallest
// region edge doubled until at most 65536 cells. Returns the mean list length.
double check_lists(const loader::BakeFile& file) {
  const loader::DdgiVolumeIndex& index = file.ddgi_index();
  const gibake_ddgi_volume_index& h = index.desc();
  std::vector<Rule> rules;
  double edge = std::numeric_limits<double>::infinity();
  for (const loader::DdgiVolume& v : file.ddgi_volumes()) rules.push_back(region(v.desc()));
  for (int a = 0; a < 3; ++a) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Rule& r : rules)
      if (r.bounded[a]) lo = std::min(lo, r.lo[a]), hi = std::max(hi, r.hi[a]), edge = std::min(edge, r.hi[a] - r.lo[a]);
    if (lo > hi) continue;
    EXPECT_LE(double(h.grid_min[a]), lo) << a;
    EXPECT_GT(double(h.grid_min[a]), lo - 1e-5 * std::max(1.0, std::fabs(lo))) << a;
    EXPECT_GE(double(h.grid_min[a]) + double(h.cell_size) * h.dims[a], hi) << a;
    EXPECT_LT(double(h.grid_min[a]) + double(h.cell_size) * (h.dims[a] - 1), hi) << a;  // no spare cell
  }
  const double doublings = std::log2(double(h.cell_size) / edge);
  EXPECT_NEAR(doublings, std::round(doublings), 1e-6);
  EXPECT_LE(h.cell_count, 65536u);
  if (doublings > 0.5) {  // the cap made it double: half the edge would have passed it
    EXPECT_GT(uint64_t(h.dims[0]) * h.dims[1] * h.dims[2] * 8, 65536u);
  }
  const std::vector<uint32_t> order = priority(file);
  const double margin = double(h.cell_size) / 16.0;
  uint64_t total = 0;
  uint32_t longest = 0;
  for (int32_t z = 0; z < h.dims[2]; ++z)
    for (int32_t y = 0; y < h.dims[1]; ++y)
      for (int32_t x = 0; x < h.dims[0]; ++x) {
        const int32_t at[3] = {x, y, z};
        std::vector<uint32_t> expected;
        for (uint32_t v : order) {
          bool meets = true;
          for (int a = 0; a < 3; ++a) {
            const double lo = double(h.grid_min[a]) + double(h.cell_size) * at[a], hi = lo + double(h.cell_size);
            meets = meets && (!rules[v].bounded[a] || (rules[v].lo[a] - margin <= hi && rules[v].hi[a] + margin >= lo));
          }
          if (meets) expected.push_back(v);
        }
        const uint32_t cell = uint32_t(x + h.dims[0] * (y + h.dims[1] * z));
        EXPECT_EQ(list(index, cell), expected) << "cell " << x << "," << y << "," << z;
        total += expected.size();
        longest = std::max(longest, uint32_t(expected.size()));
      }
  EXPECT_EQ(h.longest, longest);
  EXPECT_EQ(h.id_count, total);
  std::printf("index of %u volumes: %dx%dx%d cells of %g m, %llu ids, longest list %u\n", h.volume_count, h.dims[0],
              h.dims[1], h.dims[2], double(h.cell_size), static_cast<unsigned long long>(total), longest);
  return double(total) / double(h.cell_count);
}

// Random points over the union's box and a margin beyond, and near every volume's region faces:
// the indexed answer is the loop's to the bit, and each cell lists every volume whose region holds
// the point (so every volume of positive weight there).
void check_points(const loader::BakeFile& file, uint32_t seed, int count) {
  const loader::DdgiVolumeIndex& index = file.ddgi_index();
  const gibake_ddgi_volume_index& h = index.desc();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 1.f);
  int indexed = 0, outside_grid = 0, blended = 0, outside_all = 0;
  for (int i = 0; i < count; ++i) {
    Vec3 p;
    if (i % 2 == 0) {
      for (int a = 0; a < 3; ++a)
        p[size_t(a)] = h.grid_min[a] + h.cell_size * float(h.dims[a]) * (-0.2f + 1.4f * u(rng));
    } else {  // on or near some volume's region face
      const gibake_ddgi_volume& d = file.ddgi_volumes()[size_t(i / 2) % file.ddgi_volumes().size()].desc();
      for (int a = 0; a < 3; ++a) p[size_t(a)] = d.grid_min[a] + (d.grid_max[a] - d.grid_min[a]) * u(rng);
      const int a = i % 3;
      const float face = u(rng) < 0.5f ? d.grid_min[a] - d.spacing[a] : d.grid_max[a] + d.spacing[a];
      p[size_t(a)] = i % 7 == 1 ? face : face + (u(rng) - 0.5f) * 0.2f * std::max(d.spacing[a], 0.1f);
    }
    Vec3 n{g(rng), g(rng), g(rng)};
    const float l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (float& c : n) c /= l;
    Rgb fast, loop;
    const bool in_fast = file.sample_ddgi(p, n, fast), in_loop = file.sample_ddgi_unindexed(p, n, loop);
    ASSERT_EQ(in_fast, in_loop) << i;
    ASSERT_TRUE(same_bits(fast, loop)) << "point " << i << " (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
    uint32_t cell = 0;
    if (!index.cell_of(p, cell)) {
      ++outside_grid;
      continue;
    }
    ++indexed;
    const std::vector<uint32_t> ids = list(index, cell);
    int weighted = 0;
    for (uint32_t v = 0; v < file.ddgi_volumes().size(); ++v) {
      const loader::DdgiVolume& vol = file.ddgi_volumes()[v];
      const bool listed = std::find(ids.begin(), ids.end(), v) != ids.end();
      if (vol.region_contains(p)) {
        ASSERT_TRUE(listed) << "point " << i << ": volume " << v << " holds it, not listed";
      }
      weighted += vol.blend_weight(p) > 0.f;
    }
    blended += weighted > 1;
    outside_all += !in_loop;
  }
  std::printf("%d points: %d in the index grid, %d outside it, %d where volumes blend, %d outside every region\n",
              count, indexed, outside_grid, blended, outside_all);
  EXPECT_GT(indexed, count / 2);
  EXPECT_GT(outside_grid, count / 20);
  EXPECT_GT(blended, count / 20);
  EXPECT_GT(outside_all, 0);
}

loader::BakeFile open(const std::vector<uint8_t>& bytes) {
  loader::BakeFile file;
  const loader::Error e = file.open_borrowed(bytes.data(), bytes.size());
  EXPECT_FALSE(e) << e.message;
  return file;
}

TEST(VolumeIndex, WrittenOnlyWithSeveralVolumes) {
  const std::vector<DdgiResult> one{volume({4, 3, 5}, {0.f, 0.f, 0.f}, {1.f, 1.f, 1.f}, 901)};
  const std::vector<uint8_t> single = bake_bytes(one);
  const loader::BakeFile a = open(single);
  EXPECT_FALSE(a.ddgi_index().present());
  EXPECT_EQ(a.header().version_minor, GIBAKE_VERSION_MINOR);
  for (const gibake_section_entry& s : a.sections()) EXPECT_NE(s.type, uint32_t(GIBAKE_SECTION_DDGI_VOLUME_INDEX));
  const std::vector<uint8_t> several = bake_bytes(nested());
  const loader::BakeFile b = open(several);
  ASSERT_TRUE(b.ddgi_index().present());
  EXPECT_EQ(b.header().version_minor, GIBAKE_VERSION_MINOR_INDEX);
  EXPECT_NE(b.metadata_json().find("\"format_version\":\"1.4\""), std::string::npos) << b.metadata_json();
  EXPECT_EQ(b.sections()[size_t(b.ddgi_index().section())].format, uint32_t(GIBAKE_FORMAT_U32));
  EXPECT_EQ(b.ddgi_index().desc().volume_count, 4u);
  // Volumes given as raw sections (tests' multi_volume_bytes) are indexed too, with the same words.
  const std::vector<DdgiResult> v = nested();
  std::vector<uint8_t> raw;
  ASSERT_TRUE(test::multi_volume_bytes({&v[0], &v[1], &v[2], &v[3]}, BakeFileOptions{}, raw).is_ok());
  const loader::BakeFile c = open(raw);
  ASSERT_TRUE(c.ddgi_index().present());
  const gibake_section_entry &eb = b.sections()[size_t(b.ddgi_index().section())],
                             &ec = c.sections()[size_t(c.ddgi_index().section())];
  ASSERT_EQ(eb.size, ec.size);
  EXPECT_EQ(std::memcmp(b.section_data(uint32_t(b.ddgi_index().section())),
                        c.section_data(uint32_t(c.ddgi_index().section())), size_t(eb.size)),
            0);
}

TEST(VolumeIndex, NestedVolumesIndexedAnswerIsTheLoops) {
  const std::vector<uint8_t> bytes = bake_bytes(nested());
  const loader::BakeFile file = open(bytes);
  ASSERT_TRUE(file.ddgi_index().present());
  check_lists(file);
  check_points(file, 11, 6000);
}

TEST(VolumeIndex, ManySmallVolumesOverAOneLayerGround) {
  const std::vector<uint8_t> bytes = bake_bytes(many_fine());
  const loader::BakeFile file = open(bytes);
  ASSERT_TRUE(file.ddgi_index().present());
  const double mean = check_lists(file);
  EXPECT_LT(mean, 25.0 / 4.0) << "lists should hold a few of the 25 volumes";
  EXPECT_GE(file.ddgi_index().desc().longest, 3u);
  check_points(file, 12, 8000);
  // The ground grid (one Y layer, unbounded along Y) is listed at every height of the grid.
  uint32_t cell = 0;
  const gibake_ddgi_volume_index& h = file.ddgi_index().desc();
  for (int32_t y = 0; y < h.dims[1]; ++y) {
    const Vec3 p{-5.f, h.grid_min[1] + h.cell_size * (float(y) + 0.5f), 4.f};
    ASSERT_TRUE(file.ddgi_index().cell_of(p, cell));
    const std::vector<uint32_t> ids = list(file.ddgi_index(), cell);
    EXPECT_EQ(ids.back(), 0u) << "the coarse ground grid comes last";
  }
}

TEST(VolumeIndex, AxesOfOneProbe) {
  const std::vector<uint8_t> bytes = bake_bytes(one_probe_axes());
  const loader::BakeFile file = open(bytes);
  ASSERT_TRUE(file.ddgi_index().present());
  check_lists(file);
  check_points(file, 13, 4000);
}

// A file whose index a reader does not know (here: its type made unknown) reads as before and
// loops: the same answers.
TEST(VolumeIndex, WithoutTheIndexTheLoopAnswers) {
  std::vector<uint8_t> bytes = bake_bytes(many_fine());
  const loader::BakeFile indexed = open(bytes);
  std::vector<uint8_t> plain = bytes;
  test::table_entry(plain, size_t(indexed.ddgi_index().section()))->type = 63;
  test::reseal(plain);
  const loader::BakeFile file = open(plain);
  EXPECT_FALSE(file.ddgi_index().present());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-11.f, 11.f);
  for (int i = 0; i < 500; ++i) {
    const Vec3 p{u(rng), u(rng) * 0.3f + 2.f, u(rng)}, n{0.f, 1.f, 0.f};
    Rgb a, b;
    ASSERT_EQ(file.sample_ddgi(p, n, a), indexed.sample_ddgi(p, n, b));
    ASSERT_TRUE(same_bits(a, b)) << i;
  }
}

// Hostile index words: each rule's violation is refused with BadVolume and a message naming the section.
class HostileIndex : public ::testing::Test {
 protected:
  void SetUp() override {
    bytes_ = bake_bytes(nested());
    const loader::BakeFile file = open(bytes_);
    section_ = size_t(file.ddgi_index().section());
    header_ = file.ddgi_index().desc();
    words_.resize(size_t(file.sections()[section_].count));
    std::memcpy(words_.data(), file.section_data(uint32_t(section_)), words_.size() * 4);
  }
  // The file with the index's words replaced (same count), its checksums made to agree.
  loader::Error open_with(const std::vector<uint32_t>& words) {
    std::vector<uint8_t> bad = bytes_;
    gibake_section_entry* e = test::table_entry(bad, section_);
    std::memcpy(bad.data() + e->offset, words.data(), words.size() * 4);
    e->checksum = loader::xxh64(bad.data() + e->offset, size_t(e->size), 0);
    test::reseal(bad);
    loader::BakeFile file;
    return file.open(std::move(bad));
  }
  void expect_bad(const std::vector<uint32_t>& words, const std::string& what) {
    const loader::Error e = open_with(words);
    if (std::getenv("GIBAKE_TEST_VERBOSE")) std::printf("%s: %s\n", what.c_str(), e.message.c_str());
    EXPECT_EQ(e.code, loader::ErrorCode::BadVolume) << what << ": " << e.message;
    EXPECT_NE(e.message.find("ddgi_volume_index"), std::string::npos) << e.message;
  }
  std::vector<uint32_t> with_header(void (*edit)(gibake_ddgi_volume_index&)) const {
    std::vector<uint32_t> w = words_;
    gibake_ddgi_volume_index h = header_;
    edit(h);
    std::memcpy(w.data(), &h, sizeof h);
    return w;
  }
  uint32_t cells() const { return header_.cell_count; }
  size_t first_id() const { return 16 + cells() + 1; }
  std::vector<uint8_t> bytes_;
  std::vector<uint32_t> words_;
  gibake_ddgi_volume_index header_{};
  size_t section_ = 0;
};

TEST_F(HostileIndex, TheUntouchedWordsLoad) { EXPECT_FALSE(open_with(words_)) << "the resealing itself is sound"; }

TEST_F(HostileIndex, Header) {
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.dims[0] = 0; }), "dims 0");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.dims[2] = 70000; }), "dims beyond 65536");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.dims[1] += 1; }), "cell_count not the product");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) {
               h.dims[0] = h.dims[1] = 65536;
               h.cell_count = 0;
             }),
             "product overflowing 32 bits");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.cell_size = 0.f; }), "cell size 0");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.cell_size = std::nanf(""); }), "cell size NaN");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.grid_min[1] = INFINITY; }), "grid_min infinite");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.cell_size = 3e38f; }), "far corner infinite");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.volume_count = 3; }), "volume_count");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.id_count += 1; }), "id_count beyond the section");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.id_count = 0xFFFFFFF0u; }), "id_count huge");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.longest += 1; }), "longest");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.flags = 1; }), "flags");
  expect_bad(with_header([](gibake_ddgi_volume_index& h) { h.reserved[3] = 1; }), "reserved");
}

TEST_F(HostileIndex, Offsets) {
  std::vector<uint32_t> w = words_;
  w[16] = 1;
  expect_bad(w, "first offset 1");
  w = words_;
  w[16 + cells()] -= 1;
  expect_bad(w, "last offset short of id_count");
  w = words_;
  w[16 + cells() / 2] = 0xFFFFFFFFu;
  expect_bad(w, "an offset far beyond the ids");
  // Two cells whose offsets differ, swapped: the offsets decrease.
  w = words_;
  size_t c = 1;
  while (c < cells() && w[16 + c] == w[16 + c + 1]) ++c;
  ASSERT_LT(c, cells());
  std::swap(w[16 + c], w[16 + c + 1]);
  expect_bad(w, "decreasing offsets");
}

TEST_F(HostileIndex, Ids) {
  ASSERT_GT(header_.id_count, 0u);
  std::vector<uint32_t> w = words_;
  w[first_id()] = 4;
  expect_bad(w, "id == volume_count");
  w[first_id()] = 0xFFFFFFFFu;
  expect_bad(w, "id huge");
  // A list of two or more, reversed: out of priority order.
  size_t cell = 0;
  while (cell < cells() && words_[16 + cell + 1] - words_[16 + cell] < 2) ++cell;
  ASSERT_LT(cell, cells());
  w = words_;
  std::reverse(w.begin() + long(first_id() + words_[16 + cell]), w.begin() + long(first_id() + words_[16 + cell + 1]));
  expect_bad(w, "reversed list");
  // A volume twice in one list.
  w = words_;
  w[first_id() + words_[16 + cell] + 1] = w[first_id() + words_[16 + cell]];
  expect_bad(w, "repeated id");
}

TEST_F(HostileIndex, FormatShortAndDuplicate) {
  std::vector<uint8_t> bad = bytes_;
  test::table_entry(bad, section_)->format = GIBAKE_FORMAT_F32;
  test::reseal(bad);
  loader::BakeFile file;
  EXPECT_EQ(file.open(std::vector<uint8_t>(bad)).code, loader::ErrorCode::BadElementFormat);
  // Fewer words than the header: count and size cut to 8 words (the rest of the payload reads as
  // padding, so the checksum steps are skipped to reach the index check).
  bad = bytes_;
  gibake_section_entry* e = test::table_entry(bad, section_);
  e->count = 8;
  e->size = 32;
  test::reseal(bad);
  loader::LoadOptions unchecked;
  unchecked.verify_checksums = false;
  loader::Error err = file.open(std::vector<uint8_t>(bad), unchecked);
  EXPECT_EQ(err.code, loader::ErrorCode::BadVolume) << err.message;
  // A second index: the same words as a raw section of an unknown type, then given the index's type.
  const std::vector<DdgiResult> v = nested();
  std::vector<RawSection> extra(1);
  extra[0].type = 60;
  extra[0].format = GIBAKE_FORMAT_U32;
  extra[0].count = words_.size();
  extra[0].bytes.resize(words_.size() * 4);
  std::memcpy(extra[0].bytes.data(), words_.data(), extra[0].bytes.size());
  BakeOutputs outputs;
  outputs.ddgi = &v[0];
  for (size_t k = 1; k < v.size(); ++k) outputs.ddgi_more.push_back(&v[k]);
  outputs.extra = &extra;
  BakeFileOptions o;
  o.atlas = FloatPrecision::Full;
  std::vector<uint8_t> two;
  ASSERT_TRUE(build_bake_file(outputs, o, two).is_ok());
  const loader::BakeFile ok = open(two);
  size_t raw = 0;
  while (raw < ok.sections().size() && ok.sections()[raw].type != 60) ++raw;
  ASSERT_LT(raw, ok.sections().size());
  test::table_entry(two, raw)->type = GIBAKE_SECTION_DDGI_VOLUME_INDEX;
  test::reseal(two);
  err = file.open(std::move(two));
  EXPECT_EQ(err.code, loader::ErrorCode::DuplicateSection) << err.message;
}

}  // namespace

namespace {

// `gibake info` names the index in one line and in its JSON; a one-volume file shows neither.
TEST(VolumeIndexCli, InfoShowsTheIndex) {
  const std::string dir = test::scratch_dir("volume_index_info");
  const std::vector<uint8_t> bytes = bake_bytes(nested());
  test::write_bytes(dir + "/several.gibake", bytes);
  test::write_bytes(dir + "/one.gibake", bake_bytes({volume({3, 3, 3}, {0.f, 0.f, 0.f}, {1.f, 1.f, 1.f}, 903)}));
  const loader::BakeFile file = open(bytes);
  const gibake_ddgi_volume_index& h = file.ddgi_index().desc();
  const std::string line = "ddgi volume index: " + std::to_string(h.dims[0]) + "x" + std::to_string(h.dims[1]) + "x" +
                           std::to_string(h.dims[2]) + " cells (" + std::to_string(h.cell_count) + ") of 1.5 m, " +
                           std::to_string(h.id_count) + " volume ids, longest list " + std::to_string(h.longest) +
                           " of 4 volumes\n";
  test::RunResult r = test::run_gibake("info " + dir + "/several.gibake");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find(line), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" ddgi_volume_index u32 "), std::string::npos) << r.out;
  r = test::run_gibake_stdout("info " + dir + "/several.gibake --format json");
  EXPECT_EQ(r.exit_code, 0);
  const std::string json = "\"ddgi_index\": {\n    \"cell_count\": " + std::to_string(h.cell_count) +
                           ",\n    \"cell_size\": 1.5,\n    \"dims\": [\n      " + std::to_string(h.dims[0]) + ",\n      " +
                           std::to_string(h.dims[1]) + ",\n      " + std::to_string(h.dims[2]) + "\n    ],";
  EXPECT_NE(r.out.find(json), std::string::npos) << r.out.substr(0, 400);
  EXPECT_NE(r.out.find("\"longest_list\": " + std::to_string(h.longest) + ","), std::string::npos);
  EXPECT_NE(r.out.find("\"id_count\": " + std::to_string(h.id_count) + ","), std::string::npos);
  r = test::run_gibake("info " + dir + "/one.gibake");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.find("volume index"), std::string::npos) << r.out;
  r = test::run_gibake_stdout("info " + dir + "/one.gibake --format json");
  EXPECT_EQ(r.out.find("ddgi_index"), std::string::npos);
}

}  // namespace
