// The refined volumes traced together on the device (bake_ddgi_together, TraceStage::parts): one
// adaptive stage over every volume's probes instead of one stage per volume. A volume's rays are
// keyed by its own probe index and its stop decisions read its own blocks and grid, so each volume
// must come out byte for byte as when it is traced alone: the same rays per probe, statistics,
// states, SH, atlases and offsets. Known by construction: the half-roofed ground of
// tests/bake/refine_test.cpp, whose roof edge and slab the refinement covers with several volumes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bake/ddgi/volumes.h"
#include "bake/pipeline/devices.h"
#include "bake/run/run_context.h"
#include "tests/bake/scene_builders.h"
#include "tests/vulkan/vulkan_test_util.h"

namespace gibake {
namespace {

std::string test_device() {
  const char* env = std::getenv("GIBAKE_TEST_VULKAN_DEVICE");
  return env && *env ? env : "lavapipe";
}

// The ground (y = 0, 12 x 12 m) and the roof slab over x < 0 (y 3 to 3.1).
Scene half_roofed_ground() {
  Scene s;
  const int m = test::add_material(s, 0.5f);
  test::add_quad(s, {-6, 0, -6}, {6, 0, -6}, {6, 0, 6}, {-6, 0, 6}, {0, 1, 0}, m);
  test::add_box(s, {-6.f, 3.f, -6.f}, {0.f, 3.1f, 6.f}, false, m);
  return s;
}

enum class Route { Apart, Together, TogetherOneBlockGroups };

Status bake(const Scene& scene, Route route, std::vector<BakedVolume>& out) {
  DdgiSettings s;
  s.suns.push_back(SunLight{{0.f, -1.f, 0.f}, 50000.f, {1.f, 1.f, 1.f}});
  s.rays = 64;
  s.target_error = 0.03f;
  s.ray_budget = 256;
  s.max_rays = 1024;
  s.grid.auto_max_probes = 200;
  s.backend.backend = Backend::Vulkan;
  s.backend.vulkan_device = test_device();
  s.backend.validation = true;
  s.backend.vulkan_volumes_apart = route == Route::Apart;
  // Passes in groups of one block each: a group's blocks then come from one volume or the next.
  if (route == Route::TogetherOneBlockGroups) s.backend.vulkan_pass_group_probes = 512;
  VolumeSettings vs;
  vs.refine.budget = 2048;
  vs.refine.ray_budget = 128;
  vs.refine.rings = 0;
  Context ctx;
  const PipelineDevices platform;
  RunContext run;
  run.platform = &platform;
  return bake_ddgi_volumes(scene, s, vs, run, ctx, out);
}

// The stage's name: "trace" alone, "trace (N volumes together)" for a group's first volume.
bool has_trace_stage(const DdgiReport& r) {
  for (const auto& [name, seconds] : r.stage_seconds)
    if (name.rfind("trace", 0) == 0) return true;
  return false;
}

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_same(const BakedVolume& a, const BakedVolume& b, const std::string& what) {
  const DdgiResult& x = a.result;
  const DdgiResult& y = b.result;
  ASSERT_EQ(x.stats.size(), y.stats.size()) << what;
  for (size_t p = 0; p < x.stats.size(); ++p) {
    EXPECT_EQ(x.stats[p].rays, y.stats[p].rays) << what << " probe " << p;
    EXPECT_EQ(x.stats[p].relative_error, y.stats[p].relative_error) << what << " probe " << p;
  }
  EXPECT_EQ(x.states, y.states) << what;
  EXPECT_TRUE(same_bytes(x.sh, y.sh)) << what << ": SH";
  EXPECT_TRUE(same_bytes(x.irradiance_atlas, y.irradiance_atlas)) << what << ": irradiance atlas";
  EXPECT_TRUE(same_bytes(x.depth_atlas, y.depth_atlas)) << what << ": depth atlas";
  EXPECT_TRUE(same_bytes(x.offsets, y.offsets)) << what << ": offsets";
}

TEST(VolumesTogether, EveryVolumeComesOutAsWhenTracedAlone) {
  std::unique_ptr<vk::Context> probe;
  GIBAKE_OPEN_VULKAN_OR_SKIP(probe);
  if (!probe->shader_float64()) GTEST_SKIP() << "the test device has no doubles: no device passes";
  probe.reset();
  const Scene scene = half_roofed_ground();
  std::vector<BakedVolume> apart, together, one_block;
  Status st = bake(scene, Route::Apart, apart);
  ASSERT_TRUE(st.is_ok()) << st.message();
  st = bake(scene, Route::Together, together);
  ASSERT_TRUE(st.is_ok()) << st.message();
  st = bake(scene, Route::TogetherOneBlockGroups, one_block);
  ASSERT_TRUE(st.is_ok()) << st.message();

  // The check can fail only where there is something to share: at least two refined volumes, whose
  // probes stop after different passes.
  ASSERT_GE(apart.size(), 3u);
  ASSERT_EQ(together.size(), apart.size());
  ASSERT_EQ(one_block.size(), apart.size());
  uint32_t lo = ~0u, hi = 0;
  for (size_t v = 1; v < apart.size(); ++v) {
    ASSERT_EQ(apart[v].kind, VolumeKind::Refined);
    for (const DdgiProbeStats& p : apart[v].result.stats)
      if (p.rays > 0) lo = std::min(lo, p.rays), hi = std::max(hi, p.rays);
  }
  EXPECT_LT(lo, hi) << "the refined probes should stop after different passes";

  // Traced together: the refined volumes' stage is the first one's (its seconds there alone);
  // apart, each has its own.
  for (size_t v = 1; v < apart.size(); ++v) {
    EXPECT_TRUE(has_trace_stage(apart[v].report)) << "volume " << v;
    EXPECT_EQ(has_trace_stage(together[v].report), v == 1) << "volume " << v;
  }
  for (size_t v = 0; v < apart.size(); ++v) {
    expect_same(apart[v], together[v], "volume " + std::to_string(v) + " together");
    expect_same(apart[v], one_block[v], "volume " + std::to_string(v) + " together, one-block groups");
  }
}

}  // namespace
}  // namespace gibake
