// The GPU BVH's build is a pure function of the scene and the options, whatever the thread count,
// and the cache (bake/vulkan/bvh_cache.h) hands back exactly what a build makes: a round trip, a
// corrupt or hostile entry rebuilt, keys that follow the geometry and options, the budget, and a
// folder that cannot be written. No device needed.
#include "bake/vulkan/bvh_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "bake/vulkan/device_scene.h"
#include "io/gltf/import.h"

namespace gibake {
namespace {

Scene load(const char* rel) {
  Scene s;
  const Status st = import_scene(std::string(GIBAKE_ASSETS_DIR) + "/" + rel, {}, Context{}, s);
  EXPECT_TRUE(st) << st.message();
  return s;
}

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

TEST(GpuBvhBuild, SameBytesWhateverTheThreadCount) {
  const Scene s = load("sponza/Sponza.gltf");
  for (const bool splits : {true, false}) {
    SCOPED_TRACE(splits ? "spatial splits" : "no spatial splits");
    GpuSceneOptions o;
    o.spatial_splits = splits;
    GpuSceneData one;
    Context c1;
    c1.threads = 1;
    ASSERT_TRUE(build_gpu_scene(s, o, c1, one));
    for (const unsigned threads : {2u, 6u}) {
      Context c;
      c.threads = threads;
      GpuSceneData many;
      ASSERT_TRUE(build_gpu_scene(s, o, c, many));
      EXPECT_EQ(one.root, many.root) << threads << " threads";
      EXPECT_TRUE(same_bytes(one.nodes, many.nodes)) << threads << " threads";
      EXPECT_TRUE(same_bytes(one.triangles, many.triangles)) << threads << " threads";
    }
  }
}

struct TempDir {
  std::string path;
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "gibake_bvh_cache_XXXXXX").string();
    path = mkdtemp(t.data()) ? t : std::string();
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

void expect_same_tree(const GpuSceneData& a, const GpuSceneData& b) {
  EXPECT_EQ(a.root, b.root);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_TRUE(same_bytes(a.nodes, b.nodes));
  EXPECT_TRUE(same_bytes(a.triangles, b.triangles));
  EXPECT_TRUE(same_bytes(a.alpha_triangles, b.alpha_triangles));
}

TEST(GpuBvhCache, LoadsWhatTheBuildMadeAndRebuildsACorruptEntry) {
  const Scene s = load("sponza/Sponza.gltf");  // masked triangles too: alpha slots are packed again on a load
  TempDir dir;
  ASSERT_FALSE(dir.path.empty());
  GpuSceneData plain, first, second, repaired;
  ASSERT_TRUE(build_gpu_scene(s, {}, Context{}, plain));
  ASSERT_GT(plain.alpha_triangles.size(), 0u);
  GpuSceneOptions o;
  o.cache_dir = dir.path;
  ASSERT_TRUE(build_gpu_scene(s, o, Context{}, first));
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(first.cache_note.empty()) << first.cache_note;
  const std::string entry = dir.path + "/" + bvh_cache_key(s, BvhBuildParams{}).file_name();
  ASSERT_TRUE(std::filesystem::exists(entry));
  ASSERT_TRUE(build_gpu_scene(s, o, Context{}, second));
  EXPECT_TRUE(second.from_cache);
  expect_same_tree(plain, first);
  expect_same_tree(plain, second);
  // One flipped byte in the middle of the nodes: the checksum catches it, the tree is built again
  // (the same one) and the entry replaced.
  {
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(1000);
    char c = 0;
    f.read(&c, 1);
    c = char(c ^ 0x5a);
    f.seekp(1000);
    f.write(&c, 1);
  }
  ASSERT_TRUE(build_gpu_scene(s, o, Context{}, repaired));
  EXPECT_FALSE(repaired.from_cache);
  EXPECT_NE(repaired.cache_note.find("checksum mismatch"), std::string::npos) << repaired.cache_note;
  expect_same_tree(plain, repaired);
  GpuSceneData again;
  ASSERT_TRUE(build_gpu_scene(s, o, Context{}, again));
  EXPECT_TRUE(again.from_cache);
  // A truncated entry is rebuilt too.
  std::filesystem::resize_file(entry, 100);
  GpuSceneData truncated;
  ASSERT_TRUE(build_gpu_scene(s, o, Context{}, truncated));
  EXPECT_FALSE(truncated.from_cache);
  EXPECT_NE(truncated.cache_note.find("size does not match"), std::string::npos) << truncated.cache_note;
  expect_same_tree(plain, truncated);
}

// An entry whose checksum is right but whose tree points outside its arrays (or back up the tree,
// which would loop the traversal) is never handed to the device.
TEST(GpuBvhCache, RefusesATreeThatPointsOutsideItself) {
  TempDir dir;
  const BvhCacheKey key{1, 2};
  CachedBvh bad;
  bad.root = 0;
  bad.depth = 1;
  bad.nodes.resize(2);
  bad.triangle_of_ref = {0, 1};
  bad.nodes[0].children = {1u, GPU_LEAF_BIT | 0u, 0u, 0u};
  bad.nodes[1].children = {0u, GPU_LEAF_BIT | 1u, 0u, 0u};  // back to the root: a cycle
  ASSERT_TRUE(store_cached_bvh(dir.path, key, bad, uint64_t(1) << 30));
  CachedBvh out;
  bool found = true;
  std::string problem;
  ASSERT_TRUE(load_cached_bvh(dir.path, key, 2, out, found, problem));
  EXPECT_FALSE(found);
  EXPECT_NE(problem.find("node 1 has a child out of range"), std::string::npos) << problem;
  bad.nodes[1].children = {GPU_LEAF_BIT | (3u << GPU_LEAF_COUNT_SHIFT) | 0u, GPU_LEAF_BIT | 1u, 0u,
                           0u};  // 4 refs from 0
  ASSERT_TRUE(store_cached_bvh(dir.path, key, bad, uint64_t(1) << 30));
  ASSERT_TRUE(load_cached_bvh(dir.path, key, 2, out, found, problem));
  EXPECT_FALSE(found);
  EXPECT_NE(problem.find("child out of range"), std::string::npos) << problem;
  bad.nodes[1].children = {GPU_LEAF_BIT | 0u, GPU_LEAF_BIT | 1u, 0u, 0u};
  bad.triangle_of_ref = {0, 7};  // the scene has 2 triangles
  ASSERT_TRUE(store_cached_bvh(dir.path, key, bad, uint64_t(1) << 30));
  ASSERT_TRUE(load_cached_bvh(dir.path, key, 2, out, found, problem));
  EXPECT_FALSE(found);
  EXPECT_NE(problem.find("triangle reference out of range"), std::string::npos) << problem;
  bad.triangle_of_ref = {0, 1};
  ASSERT_TRUE(store_cached_bvh(dir.path, key, bad, uint64_t(1) << 30));
  ASSERT_TRUE(load_cached_bvh(dir.path, key, 2, out, found, problem));
  EXPECT_TRUE(found) << problem;
  ASSERT_TRUE(load_cached_bvh(dir.path, BvhCacheKey{1, 3}, 2, out, found, problem));  // no such entry
  EXPECT_FALSE(found);
  EXPECT_TRUE(problem.empty());
}

TEST(GpuBvhCache, KeysFollowTheGeometryAndTheOptions) {
  Scene s = load("box/Box.gltf");
  const BvhCacheKey base = bvh_cache_key(s, BvhBuildParams{});
  EXPECT_EQ(base.file_name(), bvh_cache_key(s, BvhBuildParams{}).file_name());
  EXPECT_NE(base.file_name(), bvh_cache_key(s, BvhBuildParams{false, 4}).file_name());
  EXPECT_NE(base.file_name(), bvh_cache_key(s, BvhBuildParams{true, 2}).file_name());
  Scene moved = s;
  moved.positions[4] += 1e-3f;
  EXPECT_NE(base.file_name(), bvh_cache_key(moved, BvhBuildParams{}).file_name());
  Scene flipped = s;
  std::swap(flipped.indices[0], flipped.indices[1]);
  EXPECT_NE(base.file_name(), bvh_cache_key(flipped, BvhBuildParams{}).file_name());
  // Materials are packed on every load, so they are not part of the key.
  Scene repainted = s;
  ASSERT_FALSE(repainted.materials.empty());
  repainted.materials[0].base_color[0] = 0.25f;
  EXPECT_EQ(base.file_name(), bvh_cache_key(repainted, BvhBuildParams{}).file_name());
}

// Past the budget the least recently used entries go; the one just written stays.
TEST(GpuBvhCache, KeepsToItsBudget) {
  TempDir dir;
  CachedBvh tree;
  tree.root = GPU_LEAF_BIT | 0u;
  tree.triangle_of_ref = {0};
  const uint64_t entry_bytes = 64 + 4;
  for (uint64_t k = 1; k <= 5; ++k) ASSERT_TRUE(store_cached_bvh(dir.path, BvhCacheKey{k, 0}, tree, 3 * entry_bytes));
  size_t kept = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path)) kept += e.path().extension() == ".gbvh";
  EXPECT_EQ(kept, 3u);
  EXPECT_TRUE(std::filesystem::exists(dir.path + "/" + BvhCacheKey{5, 0}.file_name()));
  ASSERT_TRUE(store_cached_bvh(dir.path, BvhCacheKey{6, 0}, tree, 1));  // a budget below one entry keeps the new one
  kept = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path)) kept += e.path().extension() == ".gbvh";
  EXPECT_EQ(kept, 1u);
  EXPECT_TRUE(std::filesystem::exists(dir.path + "/" + BvhCacheKey{6, 0}.file_name()));
}

// A folder that cannot be made costs the cache, never the bake.
TEST(GpuBvhCache, AnUnwritableFolderOnlyCostsTheBuild) {
  const Scene s = load("box/Box.gltf");
  TempDir dir;
  const std::string file = dir.path + "/a-file";
  std::ofstream(file) << "x";
  GpuSceneOptions o;
  o.cache_dir = file + "/cache";  // a folder under a regular file
  GpuSceneData out, plain;
  ASSERT_TRUE(build_gpu_scene(s, o, Context{}, out));
  ASSERT_TRUE(build_gpu_scene(s, {}, Context{}, plain));
  EXPECT_FALSE(out.from_cache);
  EXPECT_NE(out.cache_note.find("BVH not cached"), std::string::npos) << out.cache_note;
  expect_same_tree(plain, out);
}

}  // namespace
}  // namespace gibake
