#include "bake/vulkan/bvh_cache.h"

#include <embree3/rtcore_config.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <xxhash.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "io/bakefile/bake_file.h"
#include "io/output/bake_atomic.h"

namespace gibake {
namespace {

constexpr char kMagic[8] = {'G', 'B', 'B', 'V', 'H', 'C', '0', '1'};
constexpr uint32_t kFormat = 1;

struct EntryHeader {
  char magic[8];
  uint32_t format;
  uint32_t root;
  uint64_t key_low, key_high;
  uint32_t depth;
  uint32_t node_count;
  uint32_t ref_count;
  uint32_t reserved;
  uint64_t payload_hash;  // XXH3-64 of the nodes' bytes, then the references'
  uint64_t pad;
};
static_assert(sizeof(EntryHeader) == 64, "EntryHeader layout");

uint64_t payload_hash(const CachedBvh& b) {
  XXH3_state_t* st = XXH3_createState();
  XXH3_64bits_reset(st);
  XXH3_64bits_update(st, b.nodes.data(), b.nodes.size() * sizeof(gpu::GpuBvhNode));
  XXH3_64bits_update(st, b.triangle_of_ref.data(), b.triangle_of_ref.size() * sizeof(uint32_t));
  const uint64_t h = XXH3_64bits_digest(st);
  XXH3_freeState(st);
  return h;
}

// A child reference that stays inside the arrays; inner children come after their parent (the
// flattening is pre-order), so a tree that passes cannot loop the traversal.
bool valid_ref(uint32_t ref, uint32_t parent, const CachedBvh& b) {
  if ((ref & GPU_LEAF_BIT) != 0u) {
    const uint64_t first = ref & GPU_LEAF_FIRST_MASK;
    const uint64_t count = ((ref >> GPU_LEAF_COUNT_SHIFT) & 15u) + 1u;
    return first + count <= b.triangle_of_ref.size();
  }
  return ref < b.nodes.size() && (parent == GPU_NO_ROOT || ref > parent);
}

std::string check_tree(const CachedBvh& b, size_t scene_triangles) {
  if (b.root != GPU_NO_ROOT && !valid_ref(b.root, GPU_NO_ROOT, b)) return "root out of range";
  if (b.depth >= GPU_STACK) return "deeper than the traversal stack";
  for (uint32_t i = 0; i < b.nodes.size(); ++i)
    if (!valid_ref(b.nodes[i].children.x, i, b) || !valid_ref(b.nodes[i].children.y, i, b))
      return "node " + std::to_string(i) + " has a child out of range";
  for (const uint32_t t : b.triangle_of_ref)
    if (t >= scene_triangles) return "triangle reference out of range";
  return "";
}

// Least recently used first (loads refresh an entry's time), until the rest fit the budget.
void evict(const std::string& dir, const std::string& keep, uint64_t budget_bytes) {
  namespace fs = std::filesystem;
  struct Entry {
    fs::path path;
    fs::file_time_type time;
    uint64_t bytes;
  };
  std::vector<Entry> entries;
  uint64_t total = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("bvh-", 0) != 0 || e.path().extension() != ".gbvh") continue;
    std::error_code ec_size, ec_time;
    const uint64_t bytes = e.file_size(ec_size);
    const auto time = e.last_write_time(ec_time);
    if (ec_size || ec_time) continue;
    total += bytes;
    if (name != keep) entries.push_back({e.path(), time, bytes});
  }
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.time != b.time ? a.time < b.time : a.path < b.path; });
  for (const Entry& e : entries) {
    if (total <= budget_bytes) break;
    if (fs::remove(e.path, ec)) total -= e.bytes;
  }
}

}  // namespace

std::string BvhCacheKey::file_name() const {
  char name[64];
  std::snprintf(name, sizeof(name), "bvh-%016llx%016llx.gbvh", static_cast<unsigned long long>(high),
                static_cast<unsigned long long>(low));
  return name;
}

BvhCacheKey bvh_cache_key(const Scene& scene, const BvhBuildParams& params) {
  XXH3_state_t* st = XXH3_createState();
  XXH3_128bits_reset(st);
  const auto text = [&](const std::string& s) {
    const uint64_t n = s.size();
    XXH3_128bits_update(st, &n, sizeof n);
    XXH3_128bits_update(st, s.data(), s.size());
  };
  text("gibake GPU BVH cache");
  text(gibake_version_string());
  text(RTC_VERSION_STRING);
  const uint32_t layout[] = {kFormat,
                             uint32_t(sizeof(gpu::GpuBvhNode)),
                             uint32_t(GPU_STACK),
                             uint32_t(GPU_MAX_LEAF),
                             uint32_t(GPU_LEAF_BIT),
                             uint32_t(GPU_LEAF_COUNT_SHIFT),
                             params.spatial_splits ? 1u : 0u,
                             params.max_leaf};
  XXH3_128bits_update(st, layout, sizeof layout);
  const uint64_t sizes[] = {scene.positions.size(), scene.indices.size()};
  XXH3_128bits_update(st, sizes, sizeof sizes);
  XXH3_128bits_update(st, scene.positions.data(), scene.positions.size() * sizeof(float));
  XXH3_128bits_update(st, scene.indices.data(), scene.indices.size() * sizeof(uint32_t));
  const XXH128_hash_t h = XXH3_128bits_digest(st);
  XXH3_freeState(st);
  return {h.low64, h.high64};
}

Status load_cached_bvh(const std::string& dir, const BvhCacheKey& key, size_t scene_triangles, CachedBvh& out,
                       bool& found, std::string& problem) {
  found = false;
  problem.clear();
  out = CachedBvh{};
  const std::string path = dir + "/" + key.file_name();
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::ok();  // no entry (or none readable): built and stored
  const auto fail = [&](const std::string& why) {
    problem = path + ": " + why;
    out = CachedBvh{};
    return Status::ok();
  };
  EntryHeader h{};
  if (!in.read(reinterpret_cast<char*>(&h), sizeof h)) return fail("shorter than its header");
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0 || h.format != kFormat)
    return fail("not a cache entry of this format");
  if (h.key_low != key.low || h.key_high != key.high) return fail("holds another key");
  if (h.ref_count > GPU_LEAF_FIRST_MASK || h.node_count > 2ull * h.ref_count + 1) return fail("sizes out of range");
  const uint64_t bytes = sizeof h + uint64_t(h.node_count) * sizeof(gpu::GpuBvhNode) + uint64_t(h.ref_count) * 4;
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) != bytes || ec) return fail("size does not match its header");
  out.root = h.root;
  out.depth = h.depth;
  out.nodes.resize(h.node_count);
  out.triangle_of_ref.resize(h.ref_count);
  if (!in.read(reinterpret_cast<char*>(out.nodes.data()),
               std::streamsize(out.nodes.size() * sizeof(gpu::GpuBvhNode))) ||
      !in.read(reinterpret_cast<char*>(out.triangle_of_ref.data()), std::streamsize(out.triangle_of_ref.size() * 4)))
    return fail("read failed");
  if (payload_hash(out) != h.payload_hash) return fail("checksum mismatch");
  if (const std::string bad = check_tree(out, scene_triangles); !bad.empty()) return fail(bad);
  ::utimensat(AT_FDCWD, path.c_str(), nullptr, 0);  // used now: the last to be evicted
  found = true;
  return Status::ok();
}

Status store_cached_bvh(const std::string& dir, const BvhCacheKey& key, const CachedBvh& bvh, uint64_t budget_bytes) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::io(dir, "cannot create the BVH cache folder: " + ec.message());
  EntryHeader h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.format = kFormat;
  h.root = bvh.root;
  h.key_low = key.low;
  h.key_high = key.high;
  h.depth = bvh.depth;
  h.node_count = uint32_t(bvh.nodes.size());
  h.ref_count = uint32_t(bvh.triangle_of_ref.size());
  h.payload_hash = payload_hash(bvh);
  // Renamed into place without an fsync: an entry torn by a crash fails its checks and is rebuilt.
  AtomicFile file;
  GIBAKE_TRY(file.begin(dir + "/" + key.file_name()));
  GIBAKE_TRY(file.write(&h, sizeof h));
  GIBAKE_TRY(file.write(bvh.nodes.data(), bvh.nodes.size() * sizeof(gpu::GpuBvhNode)));
  GIBAKE_TRY(file.write(bvh.triangle_of_ref.data(), bvh.triangle_of_ref.size() * 4));
  GIBAKE_TRY(file.commit(/*durable=*/false));
  evict(dir, key.file_name(), budget_bytes);
  return Status::ok();
}

}  // namespace gibake
